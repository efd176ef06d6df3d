"""Real IMU logs that are not rocking blocks: rocklab's verdict on each, under every ``--release``.

No real rocking-block IMU log has been found in a public repository yet; these are the real logs
at hand, each of another motion, which rocklab must refuse or flag (W-IMU-NOT-ROCKING), and the
simulated rocking logs of rocklab's own sessions, which must stay clean:

- development (the bounds were checked on it): x-io's ``straightLine`` gait log (a foot-mounted
  x-IMU while walking; xioTechnologies/Gait-Tracking-With-x-IMU, read from its mirror);
- validation: the same repository's ``spiralStairs`` and ``stairsAndCorridor``, x-io's
  Oscillatory-Motion log (a sensor moved to and fro by hand), and the two logs in
  ``../shared/data/imu`` (a Fusion example spun about its vertical, an x-IMU moved by hand);
- simulated rocking: ``rocklab synth`` sessions (free rocking, a sine pulse, El Centro; one block,
  three side by side, a column), written to a temporary folder.

Printed per log and release: the kind of run read, the status, the warnings, and the measured
rocking evidence (axis above the horizontal at rest, share of the rotation about it, g RMS along
it while turning). Run: ``python benchmarks/real_imu.py [--no-synth]``.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from rocklab._diagnostics import collecting
from rocklab.blocks import G
from rocklab.tracking import block_rotation, read_imu

ROOT = Path(__file__).resolve().parents[1]
MIRRORS = Path("/work/.mirror")
GAIT = (MIRRORS / "xioTechnologies+Gait-Tracking-With-x-IMU" / "repo", "Gait Tracking With x-IMU/Datasets")
OSC = MIRRORS / "xioTechnologies+Oscillatory-Motion-Tracking-With-x-IMU" / "repo"
SHARED = ROOT.parent / "shared" / "data" / "imu"


def _from_mirror(repo: Path, path: str, dest: Path) -> Path | None:
    if not repo.is_dir():
        return None
    out = subprocess.run(["git", f"--git-dir={repo}", "show", f"HEAD:{path}"], capture_output=True)
    if out.returncode != 0:
        return None
    dest.write_bytes(out.stdout)
    return dest


def _real_logs(tmp: Path):
    """(set, name, path, rate or None) of every real log found."""
    repo, folder = GAIT
    for i, name in enumerate(("straightLine", "spiralStairs", "stairsAndCorridor")):
        p = _from_mirror(repo, f"{folder}/{name}_CalInertialAndMag.csv", tmp / f"{name}.csv")
        if p is not None:
            yield ("development" if i == 0 else "validation", f"gait {name}", p, 256.0)
    p = _from_mirror(OSC, "LoggedData/LoggedData_CalInertialAndMag.csv", tmp / "osc.csv")
    if p is not None:
        yield "validation", "oscillatory motion", p, 256.0
    yield "validation", "fusion example (spin)", SHARED / "fusion-example" / "sensor_data.csv", None
    yield "validation", "x-IMU example (by hand)", SHARED / "x-imu-matlab-library-example", None


def _synth_logs(tmp: Path):
    from rocklab.synth import synth_session

    for seed, table, blocks in ((1, "none", 1), (1, "sine", 1), (1, "record", 1), (5, "sine", 3), (6, "sine", 3)):
        d = tmp / f"s{seed}_{table}_{blocks}"
        layout = {"layout": "side"} if seed == 5 else {}
        synth_session(d, seed=seed, table=table, blocks=blocks, size=(160, 90), mp4=False, **layout)
        for b in sorted((d / "imu").glob("block_*")):
            yield "simulated", f"synth seed {seed} {table} {blocks} block(s): {b.name}", b, None


def _verdict(path, rate, release) -> str:
    log = read_imu(path, rate_hz=rate)
    with collecting() as found:
        rot = block_rotation(log, release=release)
    rk = rot.rocking
    ev = (
        f"axis {np.rad2deg(rk.axis_tilt_rad):5.1f} deg, share {100 * rk.axis_share:5.1f} %, "
        f"along {rk.lateral_acc_m_s2 / G:6.3f} g"
        if rk is not None
        else "no rotation"
    )
    codes = ",".join(sorted({d.code for d in found})) or "-"
    return f"{release:6s} {rot.run_kind:6s} {rot.status:14s} {codes:34s} {ev}"


def main(argv) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        logs = list(_real_logs(Path(tmp)))
        if "--no-synth" not in argv:
            logs += list(_synth_logs(Path(tmp)))
        for kind, name, path, rate in logs:
            for release in ("auto", "thread", "none"):
                print(f"{kind:11s} {name:44s} {_verdict(path, rate, release)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
