"""Plausibility warnings: named, documented, never silent.

Anything that degrades a result without making it impossible (a record of
implausible amplitude, a step too coarse for the block, a gap in a measured
track, an IMU whose axes disagree) is reported as a :class:`Diagnostic` with a
code from :data:`WARNING_CODES`. Severity ``"suspect"`` means the number may
be wrong and the result's status becomes ``"suspect"``; ``"note"`` means the
result stands but the user should know.

Where the diagnostic goes depends on the caller:

- inside :func:`collecting` (the CLI, the experiment pipeline) it is appended to
  the active list and echoed (the CLI prints ``rocklab CMD: warning W-CODE: ...``
  on stderr as one line);
- otherwise it is raised through Python's :mod:`warnings` as a
  :class:`RocklabWarning`, so a library user sees it too.

Results that carry a status also carry the diagnostics they raised
(``warnings`` in their ``to_dict()``).
"""

from __future__ import annotations

import contextlib
import contextvars
import warnings
from dataclasses import dataclass

__all__ = [
    "Diagnostic",
    "RocklabWarning",
    "WARNING_CODES",
    "warn",
    "collecting",
    "collected",
    "stderr_echo",
    "worst_status",
    "codes_markdown",
]

#: Every warning code: (severity, what it means and what to check). Documented in
#: ``docs/warnings.md`` (generated from this table by :func:`codes_markdown`).
WARNING_CODES: dict[str, tuple[str, str]] = {
    # records
    "W-RECORD-PGA": (
        "suspect",
        "peak acceleration above 5 g: usually a unit error (g read as m/s^2, "
        "cm/s^2 read as g); check the units field or --units",
    ),
    "W-RECORD-DT": (
        "suspect",
        "sample step above 0.05 s: too coarse for an earthquake record and often a wrong DT; check the header",
    ),
    "W-RECORD-SHORT": ("suspect", "record of fewer than 16 samples or under 0.2 s: check that the whole file was read"),
    "W-RECORD-PULSE": (
        "suspect",
        "the main pulse lasts less than 2 samples: t_p cannot be resolved; "
        "check the record's sampling and zero padding",
    ),
    # simulation
    "W-COLUMN-APART": (
        "note",
        "column runs stopped with a joint in tension or sliding (the column comes apart, which the "
        "rocking model cannot follow): counted as unsafe in overturning maps and spectra; see their "
        "stopped / n_terminated counts",
    ),
    "W-SIM-DT": (
        "suspect",
        "time step dt is large against the block's 1/p (p dt > 0.01): "
        "impact times and rocking amplitudes are not converged; use a smaller --dt",
    ),
    # fitting
    "W-FIT-GAP": (
        "suspect",
        "the measured theta(t) has a gap (lost frames) long enough to hide an impact; the "
        "fit uses the data before the gap",
    ),
    "W-FIT-DUPLICATE": (
        "suspect",
        "repeated rows in a block table were dropped (each block counted once); check the "
        "file was not concatenated twice",
    ),
    "W-FIT-THETA0": (
        "suspect",
        "the measured release angle is large for the block's geometry "
        "(theta0 above 0.9 alpha): check b and h (swapped, "
        "or in cm instead of m)",
    ),
    "W-FIT-RESIDUAL": (
        "suspect",
        "the fitted simulation misses the measurement by more than 20x the noise (at least "
        "1e-3 rad): the model or the block's dimensions do not describe this test",
    ),
    "W-FIT-RELEASE": (
        "suspect",
        "the release time is not decided: release times more than 3 samples apart fit the plateau "
        "and the first quarter-cycle alike, and eta depends on which is right; check the record's "
        "start and the block's dimensions",
    ),
    "W-FIT-BOUND": ("suspect", "the fitted parameter sits at a bound of its search range"),
    "W-VALID-ASSUMED": (
        "note",
        "a shake-table run's validation assumed the table acceleration's noise (2 % of its peak): the "
        "table motion is a record (the command, not a measurement) or its log has no rest before the "
        "shaking; its bands and verdicts rest on that guess. Log the table with an IMU from rest",
    ),
    "W-FIT-UNITS": (
        "suspect",
        "block dimensions outside 1 mm - 20 m or h/b outside 0.5 - 50: probably not in metres, or b and h swapped",
    ),
    # IMU
    "W-IMU-AXES": (
        "suspect",
        "the gyro's integral and the accelerometer's tilt disagree in sign or "
        "scale: axes swapped, rotation axis wrong, or gyro units wrong "
        "(rad/s in a deg/s column); check the column names and --axis",
    ),
    "W-IMU-CLOCK": (
        "suspect",
        "the log's clock jumps or has a gap: samples are missing or the "
        "timestamps are corrupt; impacts in the gap are lost",
    ),
    "W-IMU-COLUMN-SYNC": (
        "suspect",
        "a column's level IMUs were put on one clock by cross-correlating the acceleration spikes of "
        "their impacts, and a level correlates weakly (peak below 0.4): its events may be shifted "
        "against the others'; record a film (each IMU is then synced to its tracked block) or start "
        "the loggers together",
    ),
    "W-IMU-RATE": (
        "suspect",
        "sample rate disagrees between the option, the log's register and its timestamps; the timestamps were trusted",
    ),
    "W-IMU-TRUNCATED": ("note", "an incomplete final line (logger stopped mid-write) was dropped"),
    "W-IMU-NOT-ROCKING": (
        "suspect",
        "the log is not a rocking block: its rotation axis is far from horizontal (a spin "
        "about the vertical), the rotation is spread over several axes (a hand-held sensor), "
        "it turns through more than a half turn, holding the rests needs a large gyro "
        "drift, it accelerates along the rocking axis while it turns (a foot while walking, "
        "whatever --release says: a rocking edge stays put along itself), released from rest "
        "its half swings grow (a released block only loses energy), or, read as a forced run, "
        "it starts to turn with no push from a table; theta, release and impacts mean nothing. "
        "Check the file and the mounting (a shake-table run read as a release: --release none; "
        "a release read as a forced run: --release auto; each keeps every other test)",
    ),
    "W-IMU-NO-REST": (
        "suspect",
        "the IMU log does not start (or end) at rest: the gyro bias and the starting tilt come from moving "
        "samples (or the drift is not held by a final rest), so theta drifts; log from before the release "
        "until the block has rested",
    ),
    "W-IMU-TABLE": (
        "suspect",
        "the table sensor turned during the log (gyro or the gravity of its first and last "
        "rests): gravity, removed in the orientation at the first rest, leaks into the table "
        "acceleration by 2 g sin(turn/2); check that the sensor is fixed to the table",
    ),
    "W-TABLE-FUSION": (
        "suspect",
        "the table IMU and the film's table disagree beyond their noise: the film's displacement departs "
        "from the IMU's twice-integrated acceleration, or the IMU reads an offset larger than a level table "
        "gives (0.05 m/s2, 0.3 deg of tilt); the fused table follows the film at low frequencies. Check the "
        "table IMU's scale and mounting, the sync and the film's metric scale",
    ),
    # video tracking
    "W-TRACK-NOSCALE": (
        "note",
        "no metric scale (marker size, object size, m_per_px, homography): x_m and y_m "
        "are left empty; x_px, y_px and theta_rad are measured",
    ),
    "W-LEVEL-NONE": (
        "suspect",
        "levelling asked for a reference that is not there (a table missing or never seen, or a "
        "block with no final rest: the message says what its angle did): the camera's roll "
        "stays in every angle; add a level reference or say the camera is level",
    ),
    "W-THETA0-REST": (
        "note",
        "a markerless block without theta0_rad came to rest away from upright: its starting "
        "angle was taken from the final rest (free rocking ends upright); set theta0_rad if "
        "the block really rests tilted",
    ),
    "W-TABLE-MOTION": (
        "suspect",
        "the table's displacement could not be differentiated into velocity and "
        "acceleration (too few consecutive samples, or no metric scale); no "
        "<stem>_table.csv was written",
    ),
    "W-TRACK-THETA": (
        "suspect",
        "a block's appearance does not change when it turns (a disk, a plain ball, a region with "
        "no edge or mark off its centre), or its outline is round and its region no longer matches "
        "a turned copy of its first view or, its shading taken out, its texture tells no angle and it "
        "is seen too briefly to judge its views (a plain lit ball thrown through): its angle is not measured; theta_rad is NaN and x, y "
        'are tracked (for an appearance that tells no angle: its centre of symmetry). Set kind = "point" for a position '
        "only, or redraw the region",
    ),
    "W-TRACK-LATCH": (
        "suspect",
        "a tracker follows another object: a table that turns, or two objects on the "
        "same pixels (the frames of the one that jumped there are status latch); redraw the "
        "region (or fix the marker ids) of the named object",
    ),
    "W-TRACK-TWIN": (
        "suspect",
        "an object found again after lost frames beside a look-alike (identical pucks) whose motion "
        "before the loss does not tell which of the two it is: those frames are status twin, not ok; "
        "track the look-alike too, or track the object over the frames it is not beside it",
    ),
    "W-VIDEO-SHORT": (
        "note",
        "the container's header counts more frames than the file holds: the file was cut, or its "
        "header over-counts; the frames there are measured",
    ),
    "W-VIDEO-DROPPED": (
        "note",
        "the camera dropped frames: slots of the container's constant clock hold no frame; every "
        "frame keeps its own time, the gaps are in t_s",
    ),
    "W-VIDEO-CUT": (
        "suspect",
        "the tracked frames cut to another shot (a title card, a lead-in, an edit): frames after "
        "the cut show another scene, and a first frame from another shot gives the objects' "
        "templates and background; set [video] start_frame (and stop_frame) to a span of one shot",
    ),
    "W-VIDEO-DAMAGED": (
        "suspect",
        "frames the container holds did not decode (damaged packets): the frames around them are "
        "measured at their own times, the gaps are in t_s; check the copy of the file",
    ),
    "W-VIDEO-COUNT": (
        "suspect",
        "the reader delivered frames past the ones the container's times cover (a container whose "
        "count or times are wrong): those frames are timed at the frame rate after the last "
        "known time; check the film (convert it to .mkv/.mp4 with ffmpeg) or give --fps",
    ),
    "W-VIDEO-FPS": (
        "suspect",
        "a frame rate given in the config or with --fps contradicts the container's own clock: "
        "t_s follows the given rate; remove it unless the film's clock is known wrong",
    ),
    "W-VIDEO-TIMES": (
        "suspect",
        "a high-speed film's own frame times contradict its frame rate (a frame stamped far from "
        "the others: a damaged or cut time block): t_s follows the rate; check the frames named",
    ),
    "W-VIDEO-MIRRORED": (
        "suspect",
        "the film's display matrix mirrors the picture: it is tracked as shown, so theta's sign is "
        "the mirrored picture's; check it against the lab, or re-mux the film without the mirror",
    ),
    "W-VIDEO-CAMERA": (
        "suspect",
        "the camera moves: the background outside the objects' regions shifts, where they are, by more than "
        "3 px from the first frame tracked in at least a quarter of the frames compared; positions in image pixels (and "
        "metres and angles from them) include the camera's motion. Film from a fixed camera (a tripod)",
    ),
    "W-VIDEO-LOST": ("suspect", "an object was lost on more than 1 % of the frames (see the status column)"),
    # 3D points and the assumption audit
    "W-3D-LOST": (
        "suspect",
        "a body had no pose (fewer than 3 of its points seen) in more than 1 % of the samples (see the status column)",
    ),
    "W-3D-REST": (
        "suspect",
        "no upright rest found at the end of the 3D record: theta is measured from another "
        "pose and may carry a constant tilt; give --rest T0,T1",
    ),
    "W-3D-RATE": (
        "suspect",
        "the 3D record's median time step is outside 10 Hz - 20 kHz: t_s is probably not in "
        "seconds (ms gives 1000x fewer Hz); every rate, impact time and velocity is off",
    ),
    "W-3D-SIZE": (
        "suspect",
        "a body's targets span less than 2 mm or more than 20 m: the coordinates are "
        "probably not in metres (mm under x_m); name the columns x_mm, y_mm, z_mm",
    ),
    "W-3D-UP": (
        "suspect",
        "--up is not the rig's vertical: the block's rotation axis is far from horizontal, or "
        "its centroid falls (reversed axis) or sways with the sign of theta (a horizontal axis) "
        "when it tilts; theta, pivots and uplift are measured in the wrong frame",
    ),
    "W-AUDIT": (
        "suspect",
        "the test broke the planar-rocking assumptions (sliding, jumping, twist, out-of-plane "
        "rotation or a double impact beyond tolerance): see audit.json for the impacts "
        "affected; fits through them are not trustworthy",
    ),
    # imports from other tools
    "W-IMPORT-TIME": (
        "suspect",
        "an imported trajectory has two rows at one time (a Kinovea export): that time is left out "
        "(lost) for it, as the file does not say which row is the film's; check the trajectory there",
    ),
    "W-STEREO-NOSYNC": (
        "suspect",
        "the films were taken as triggered together (--no-sync), but a clock offset between them "
        "fits the targets' epipolar lines far better: the 3D points of moving targets are skewed; "
        "run without --no-sync",
    ),
    "W-CALIB-WEAK": (
        "suspect",
        "a camera calibration is weakly determined: a focal length's 1-sigma exceeds 1 % of it (too few "
        "views, or views that do not tilt the board), or the reprojection RMS exceeds 1 px (a wrong board "
        "spec, blur, a bent or moving board; for two cameras, photos paired wrongly); a lens file carries "
        "status 'weak'",
    ),
}


class RocklabWarning(UserWarning):
    """A plausibility warning raised outside a :func:`collecting` block (see :data:`WARNING_CODES`)."""

    def __init__(self, diagnostic: "Diagnostic"):
        super().__init__(f"{diagnostic.code}: {diagnostic.message}")
        self.diagnostic = diagnostic


@dataclass(frozen=True)
class Diagnostic:
    """One plausibility warning.

    Attributes
    ----------
    code : str
        A key of :data:`WARNING_CODES` (``"W-..."``).
    message : str
        One line: what was found, with numbers and units, and what to check.
    severity : str
        ``"suspect"`` (the result may be wrong) or ``"note"``.
    """

    code: str
    message: str
    severity: str = "suspect"

    def to_dict(self) -> dict:
        """``{"code", "message", "severity"}``."""
        return {"code": self.code, "message": self.message, "severity": self.severity}

    def line(self, command: str = "") -> str:
        """The stderr line: ``rocklab CMD: warning W-CODE: message``."""
        pre = f"rocklab {command}: " if command else "rocklab: "
        return f"{pre}warning {self.code}: {self.message}"


_active: contextvars.ContextVar = contextvars.ContextVar("rocklab_diagnostics", default=None)


def warn(code: str, message: str) -> Diagnostic:
    """Report a plausibility warning ``code`` (a key of :data:`WARNING_CODES`) with a one-line message.

    Returns the :class:`Diagnostic` so a result object can keep it.
    """
    if code not in WARNING_CODES:  # a programming error, not bad input
        raise KeyError(f"unknown warning code {code!r}; add it to WARNING_CODES")
    d = Diagnostic(code, " ".join(str(message).split()), WARNING_CODES[code][0])
    sink = _active.get()
    if sink is None:
        warnings.warn(RocklabWarning(d), stacklevel=2)
    elif d not in sink[0]:  # the same finding reported twice is one warning
        while sink is not None:  # every enclosing collector sees it; the outermost echo prints it
            sink[0].append(d)
            if sink[1] is not None:
                sink[1](d)
            sink = sink[2]
    return d


@contextlib.contextmanager
def collecting(echo=None):
    """Collect the diagnostics raised inside the block into the yielded list.

    Parameters
    ----------
    echo : callable(Diagnostic), optional
        Called once per new diagnostic as it is raised (the CLI prints it). Ignored
        inside another :func:`collecting` block: the enclosing one echoes, and
        receives the diagnostics too.
    """
    found: list[Diagnostic] = []
    parent = _active.get()
    token = _active.set((found, echo if parent is None else None, parent))
    try:
        yield found
    finally:
        _active.reset(token)


def collected() -> list[Diagnostic]:
    """The diagnostics gathered so far by the innermost active :func:`collecting` block
    (empty outside one)."""
    sink = _active.get()
    return list(sink[0]) if sink is not None else []


def stderr_echo(command: str):
    """An ``echo`` for :func:`collecting` that prints each diagnostic as its one stderr line."""
    import sys

    def echo(d: Diagnostic) -> None:
        sys.stderr.write(d.line(command) + "\n")
        sys.stderr.flush()

    return echo


def worst_status(status: str, diagnostics) -> str:
    """``status`` downgraded to ``"suspect"`` when it is ``"ok"`` and a diagnostic is suspect."""
    if status == "ok" and any(d.severity == "suspect" for d in diagnostics):
        return "suspect"
    return status


def codes_markdown() -> str:
    """The table of warning codes as Markdown (for the docs)."""
    rows = ["| code | severity | meaning and what to check |", "| --- | --- | --- |"]
    rows += [f"| `{c}` | {s} | {m} |" for c, (s, m) in WARNING_CODES.items()]
    return "\n".join(rows) + "\n"
