"""Every real film of the reviewers' kits, tracked from four boxes and checked against an independent reference.

One command instead of three kits outside the repository (review16, review18, review19 under
``/work/scratch``; ``benchmarks/_film_refs.py`` has the films, their provenance and the ported
references). For each film that is at hand (its ``fetch`` mirror, ``/work/.mirror/<owner>+<name>``,
or ``$ROCKLAB_FILMS/<name>.<ext>``; otherwise skipped, said so) and each box variant (the box drawn
by eye, ``base``; moved by +10 % of its size in x and y, ``shift+10``; scaled 120 % and 80 % about
its centre, ``s120``, ``s080``; rounded as its kit did), this runs the kits' path: ``rocklab track
init FILM --object NAME=x,y,w,h [--start-frame N] [--fps F] -o cfg.toml`` then ``rocklab track FILM
--config cfg.toml -o tracks.csv --json`` (this checkout's rocklab, in a subprocess), and counts per
object against the reference (computed here, from the film, every run):

- frames, ``ok`` frames;
- ok but wrong: an ``ok`` frame farther than 1 % of the frame width from the expected point, by the
  film's kit's rule: review16 ("carried": the reference point or the first box centre carried by
  its translation, or for necros_ball by the string's turn about (306, 100), whichever is nearest;
  katie_pendulum "pendulum": the box centre carried by the rod's rotation about the pivot, which
  moves with the hand-held camera), review18 ("direct": the reference centroid, in the frames it is
  in plain view: found, off the frame's edge, not in ``hidden`` frames or touching an occluder),
  review19 ("relative": displacements from the first frame, plain view as review18);
- ok frames with no reference (not judged), the largest error;
- theta: ok frames with an angle, and (katie_pendulum, the one film whose kit measured the angle)
  those off by more than max(3 sigma, 2 deg) from the rod's rotation;
- the other statuses and the warning codes.

The tracks are always made afresh into ``OUT/runs/<film>/<box>/`` (the old ``tracks.csv`` is
deleted first) and the table is computed from this run's tracks only: the kits' ``compare.py``
read whatever was in ``runs/`` and once reported a stale run's figures. ``--eval-only`` re-reads
tracks a previous run left, and says the commit they were made at.

Run (from the repository's root; the machine's cores shared: one film at a time)::

    NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 python benchmarks/real_films.py [NAME_PART ...]
        [--boxes base,shift+10,s120,s080] [--out /tmp/real_films] [--eval-only]

Writes ``OUT/real_films.md`` (the table) and ``OUT/real_films.csv``. Development vs validation is
the ``set`` column: a film is development for the change a session tuned on it (CHANGELOG).
Nothing of these films is shipped or run in CI; most of the repositories state no licence.
"""

from __future__ import annotations

import argparse
import collections
import csv
import json
import math
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _film_refs import FILMS, materialise, perturb, references, rot  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
KINDS = ["base", "shift+10", "s120", "s080"]


def _commit():
    # the package's state, not the benchmark's: uncommitted edits under rocklab/ are said
    git = ["git", "-C", str(ROOT)]
    head = subprocess.run([*git, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run([*git, "status", "--porcelain", "--", "rocklab"], capture_output=True, text=True).stdout
    return head + ("+uncommitted rocklab/ edits" if dirty.strip() else "")


def _cpu_children():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def track(film, path, kind, out):
    """Init + track one box variant through the CLI; returns the run's record (exit codes, times, warnings)."""
    d = out / "runs" / film.name / kind
    if d.exists():
        shutil.rmtree(d)  # never read a previous run's tracks
    d.mkdir(parents=True)
    boxes = {o: perturb(b, kind, film.size, film.rounding) for o, b in film.boxes.items()}
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    rl = [sys.executable, "-m", "rocklab", "track"]
    fps = ["--fps", str(film.fps)] if film.fps else []
    init = [
        *rl,
        "init",
        str(path),
        *[a for o, b in boxes.items() for a in ("--object", f"{o}={','.join(map(str, b))}")],
    ]
    init += [*(["--start-frame", str(film.start)] if film.start else []), *fps, "-o", str(d / "cfg.toml")]
    run = [*rl, str(path), "--config", str(d / "cfg.toml"), "-o", str(d / "tracks.csv"), "--json", *fps]
    rec = {"film": film.name, "box": kind, "boxes": boxes, "commit": _commit()}
    for step, cmd in (("init", init), ("track", run)):
        t0, c0 = time.perf_counter(), _cpu_children()
        p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
        rec[f"{step}_rc"], rec[f"{step}_wall_s"] = p.returncode, round(time.perf_counter() - t0, 1)
        rec[f"{step}_cpu_s"] = round(_cpu_children() - c0, 1)
        (d / f"{step}.err").write_text(p.stderr)
        if step == "track":
            (d / "track.json").write_text(p.stdout)
        if p.returncode:
            rec["error"] = (p.stderr.strip().splitlines() or ["?"])[-1][:160]
            break
    (d / "run.json").write_text(json.dumps(rec, indent=1))
    return rec


def _rows(d, obj):
    p = d / "tracks.csv"
    if not p.exists():
        return None
    return [r for r in csv.DictReader(p.open()) if r["object"] == obj]


def _f(s):
    return float(s) if s not in ("", None) else np.nan


def _at(a, f):
    return a[f] if 0 <= f < len(a) else np.full(a.shape[1], np.nan)


def judge_carried(film, rows, ref, box, extra):
    """review16 ``evaluate.py``: per ok row (frame, error px or NaN, theta verdict or None)."""
    c0 = np.array([box[0] + box[2] / 2, box[1] + box[3] / 2])
    r0 = _at(ref, film.start)[:2]
    knob = extra.get("knob")
    if knob is not None:
        dpiv = np.array([1.0, 15.0])  # by hand on f0: the rod meets the bracket 15 px below the knob
        piv = knob[film.start] + dpiv
        phi0 = math.atan2(r0[1] - piv[1], r0[0] - piv[0])
    out = []
    for r in rows:
        f, p = int(r["frame"]), np.array([_f(r["x_px"]), _f(r["y_px"])])
        rf = _at(ref, f)[:2]
        if not np.all(np.isfinite(rf)):
            out.append((f, np.nan, None))
            continue
        if knob is None:
            cands = [rf, rf + c0 - r0]
            if film.pivot:  # a bob on a string: the box centre's offset turns with the string too
                pv = np.array(film.pivot)
                a = math.atan2(*(rf - pv)[::-1]) - math.atan2(*(r0 - pv)[::-1])
                cands.append(rf + rot(a) @ (c0 - r0))
            out.append((f, min(float(np.linalg.norm(p - c)) for c in cands), None))
            continue
        pv = knob[f] + dpiv
        dphi = math.atan2(rf[1] - pv[1], rf[0] - pv[0]) - phi0
        e = float(np.linalg.norm(p - (pv + rot(dphi) @ (c0 - piv))))
        th, sg = _f(r["theta_rad"]), _f(r["sigma_theta_rad"])
        # the kit's max(3 sigma, 2 deg) with Python's max: a NaN sigma never counts a frame wrong
        bad = None if not np.isfinite(th) else bool(abs(th + dphi) > max(3 * sg, math.radians(2.0)))
        out.append((f, e, bad))
    return out


def judge_view(film, rows, ref, relative):
    """review18/19 ``compare.py``: per ok row (frame, error px or NaN where not in plain view, None)."""
    W, H = film.size
    f0 = int(rows[0]["frame"]) if rows else 0
    p0 = np.array([_f(rows[0]["x_px"]), _f(rows[0]["y_px"])]) if rows else np.zeros(2)
    q0 = _at(ref, f0)[:2]
    out = []
    for r in rows:
        f = int(r["frame"])
        x, y, area, bx, by, bw, bh = _at(ref, f)
        vis = area >= film.min_area and bx > 1 and by > 1 and bx + bw < W - 1 and by + bh < H - 1
        vis = vis and not any(lo <= f <= hi for lo, hi in film.hidden)
        vis = vis and not any(bx <= hi and bx + bw >= lo for lo, hi in film.occluder_x)
        p, q = np.array([_f(r["x_px"]), _f(r["y_px"])]), np.array([x, y])
        if relative:
            p, q = p - p0, q - q0
        out.append((f, float(np.hypot(*(p - q))) if vis else np.nan, None))
    return out


def evaluate(film, kind, out, refs):
    """Table rows for one box variant: one per object and reference."""
    d = out / "runs" / film.name / kind
    rec = json.loads((d / "run.json").read_text()) if (d / "run.json").exists() else {}
    try:
        warn = sorted({w["code"] for w in json.loads((d / "track.json").read_text()).get("warnings", [])})
    except (OSError, ValueError):
        warn = []
    tol = 0.01 * film.size[0]
    res = []
    for label, per_obj in refs.items():
        for obj, box in film.boxes.items():
            box = perturb(box, kind, film.size, film.rounding)
            row = dict(film=film.name, set=film.data_set, kit=film.kit.split()[0], box=kind, object=obj,
                       roi=",".join(map(str, box)), reference=label, commit=rec.get("commit", "?"))  # fmt: skip
            rows = _rows(d, obj)
            if rows is None:
                res.append({**row, "error": rec.get("error", "no tracks.csv")})
                continue
            ok = [r for r in rows if r["status"] == "ok"]
            if film.rule in ("carried", "pendulum"):
                j = judge_carried(film, ok, per_obj[obj], box, per_obj)
            else:
                j = judge_view(film, rows, per_obj[obj], film.rule == "relative")
                j = [x for x, r in zip(j, rows) if r["status"] == "ok"]
            e = np.array([x[1] for x in j], float)
            st = collections.Counter(r["status"] for r in rows)
            st.pop("ok", None)
            th = [r for r in ok if np.isfinite(_f(r["theta_rad"]))]
            row.update(frames=len(rows), ok=len(ok), ok_wrong=int(np.sum(e > tol)), ok_noref=int(np.isnan(e).sum()),
                       max_err_px=round(float(np.nanmax(e)), 1) if np.isfinite(e).any() else "",
                       tol_px=round(tol, 2), theta_ok=len(th),
                       theta_wrong=sum(1 for x in j if x[2]) if film.rule == "pendulum" else "",
                       not_ok=" ".join(f"{k}:{v}" for k, v in st.most_common()), warnings=" ".join(warn),
                       track_wall_s=rec.get("track_wall_s", ""), track_cpu_s=rec.get("track_cpu_s", ""),
                       init_wall_s=rec.get("init_wall_s", ""), init_cpu_s=rec.get("init_cpu_s", ""))  # fmt: skip
            res.append(row)
    return res


COLS = ["film", "set", "box", "object", "roi", "reference", "frames", "ok", "ok_wrong", "ok_noref", "max_err_px",
        "tol_px", "theta_ok", "theta_wrong", "not_ok", "track_wall_s", "track_cpu_s"]  # fmt: skip


def markdown(rows):
    """The table as markdown (an errored run says its last line)."""
    lines = ["| " + " | ".join(COLS) + " |", "|" + "---|" * len(COLS)]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['film']} | {r['set']} | {r['box']} | {r['object']} | {r['roi']} | {r['reference']} | "
                         f"error: {r['error']} |" + " |" * (len(COLS) - 7))  # fmt: skip
        else:
            lines.append("| " + " | ".join(str(r.get(c, "")) for c in COLS) + " |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help="part of a film's name (default: every film)")
    ap.add_argument("--boxes", default=",".join(KINDS), help="box variants, comma-separated")
    ap.add_argument("--out", default="/tmp/real_films", help="output folder (tracks, table, CSV)")
    ap.add_argument("--cache", default=None, help="where films taken out of the mirrors go (default OUT/films)")
    ap.add_argument("--eval-only", action="store_true", help="re-evaluate the tracks a previous run left")
    a = ap.parse_args(argv)
    out = Path(a.out)
    kinds = [k for k in a.boxes.split(",") if k]
    bad = set(kinds) - set(KINDS)
    if bad:
        ap.error(f"--boxes: unknown {sorted(bad)}; choose from {KINDS}")
    table = []
    t_all, c_all = time.perf_counter(), time.process_time() + _cpu_children()
    for film in FILMS:
        if a.names and not any(n in film.name for n in a.names):
            continue
        path = materialise(film, Path(a.cache) if a.cache else out / "films")
        if path is None:
            print(f"{film.name}: mirror of {film.repo} absent and not in $ROCKLAB_FILMS: skipped", flush=True)
            continue
        if a.eval_only and not (out / "runs" / film.name).exists():
            print(f"{film.name}: no tracks in {out / 'runs'}: skipped", flush=True)
            continue
        t0 = time.perf_counter()
        refs = references(film, path)
        print(f"{film.name} ({film.data_set}; {film.kit}): reference {time.perf_counter() - t0:.0f} s", flush=True)
        for kind in kinds:
            if not a.eval_only:
                rec = track(film, path, kind, out)
                print(f"  {kind}: init {rec.get('init_wall_s')} s, track {rec.get('track_wall_s', '-')} s wall, "
                      f"{rec.get('track_cpu_s', '-')} s CPU {rec.get('error', '')}", flush=True)  # fmt: skip
            rows = evaluate(film, kind, out, refs)
            for r in rows:
                print("   ", {k: r.get(k) for k in ("object", "reference", "frames", "ok", "ok_wrong", "theta_ok",
                                                   "theta_wrong", "max_err_px", "not_ok", "error") if k in r},
                      flush=True)  # fmt: skip
            table += rows
    wall, cpu = time.perf_counter() - t_all, time.process_time() + _cpu_children() - c_all
    out.mkdir(parents=True, exist_ok=True)
    made = sorted({str(r.get("commit")) for r in table})
    md = (
        markdown(table)
        + f"\n\ntracks made at rocklab {', '.join(made)}; this run: {'evaluation only, ' if a.eval_only else ''}"
        + f"wall {wall:.0f} s, CPU {cpu:.0f} s (this process and its children)\n"
    )
    (out / "real_films.md").write_text(md)
    with (out / "real_films.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=[*COLS, "kit", "commit", "warnings", "init_wall_s", "init_cpu_s", "error"])
        w.writeheader()
        w.writerows(table)
    print(md)


if __name__ == "__main__":
    main()
