"""Screenshots of recordings in Rerun's web viewer for the README (docs/img/viewer_*.png).

Each scenario is run, recorded as ``fsarm run SCENARIO --rrd`` would record it, opened in Rerun's
web viewer in headless Chromium and checked the way tests/test_viewer_check.py checks it (every
view drawn, the loop panels framed to their data); the screenshot is written only when the check
passes, and what was measured is printed.

    .venv/bin/python scripts/viewer_screenshots.py [--out docs/img] [SCENARIO ...]
    .venv/bin/python scripts/viewer_screenshots.py --rrd FILE.rrd --name NAME  # any recording
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import viewer_check
from fsarm_sim.review import recording
from fsarm_sim.sim.simulation import run_scenario

DEFAULT = ("fig14-sine", "p2p-payload")
RATE_HZ = 50.0  # rows per simulated second in the recording (a smaller file loads faster)


def shoot(rrd: Path, name: str, out: Path, expected: int | None, text_views: int = 1) -> bool:
    shot = viewer_check.screenshot(
        rrd, expected_views=expected, text_views=text_views, timeout_s=240.0
    )
    print(f"{name}: {len(shot.views)} views in {shot.seconds:.0f} s", flush=True)
    for v in shot.views:
        share = v.data_share
        extra = f", loop data fill {share[0]:.2f} x {share[1]:.2f} of its axes" if share else ""
        print(f"  {v.box}: ink {v.ink:.3f}, colour {v.colour:.4f}{extra}", flush=True)
    ok = not shot.blank and (expected is None or len(shot.views) == expected)
    if ok:
        out.mkdir(parents=True, exist_ok=True)
        (out / f"viewer_{name}.png").write_bytes(shot.png)
        print(f"  -> {out / f'viewer_{name}.png'}", flush=True)
    else:
        print(f"  check failed: blank views {[v.box for v in shot.blank]}", file=sys.stderr)
    return ok


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*", default=list(DEFAULT))
    ap.add_argument("--out", type=Path, default=Path("docs/img"))
    ap.add_argument("--rrd", type=Path, help="screenshot this recording instead of running")
    ap.add_argument("--name", default="recording", help="name of the --rrd screenshot")
    args = ap.parse_args()
    if args.rrd is not None:
        # any recording: its views may be black on white (a measured curve), so only "not blank"
        return 0 if shoot(args.rrd, args.name, args.out, None, text_views=99) else 1
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenarios:
            result = run_scenario(name)
            rrd = Path(tmp) / f"{name}.rrd"
            recording.record_run(result, rrd, rate_hz=RATE_HZ)
            cols = recording.with_derived(result.columns)
            loops = sum(recording.loop_is_informative(lp, cols) for lp in recording.ARM_LOOPS)
            expected = 2 + loops + len(recording.shown_panels(recording.run_panels(result)))
            ok = shoot(rrd, name, args.out, expected) and ok
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
