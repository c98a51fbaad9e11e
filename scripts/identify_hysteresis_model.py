"""Identify the default of the controller's Maxwell-slip model (``data/hysteresis_model.toml``).

Runs seed 000's series test (a chirp at 0.8 of the rating into the blocked bench's torque loop,
slower than the paper's 0.5-20 Hz: studies/hysteresis_id.py says why) on the simulated bench of a catalogue shaft at held bends 0/45/90 deg, fits the controller's
model to those records (:func:`fsarm_sim.studies.hysteresis_id.identify`: the bench's torque
sensor against the encoders) and writes it as fractions of the shaft's eq. 3 and rating. The
controller never reads the plant's slip parameters: this is the only way the default is made.

    .venv/bin/python scripts/identify_hysteresis_model.py [--diameter-mm 9 --length-mm 450]
        [--write]      # overwrite src/fsarm_sim/data/hysteresis_model.toml (else print it)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from fsarm_sim.plant.shaft import load_catalogue
from fsarm_sim.studies import hysteresis_id

DATA = Path(__file__).resolve().parents[1] / "src" / "fsarm_sim" / "data" / "hysteresis_model.toml"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--diameter-mm", type=float, default=9.0)
    ap.add_argument("--length-mm", type=float, default=450.0)
    ap.add_argument("--write", action="store_true")
    a = ap.parse_args()
    shaft = load_catalogue().shaft(a.diameter_mm, a.length_mm, series_hysteresis=True)
    t0 = time.perf_counter()
    model = hysteresis_id.identify_shaft(shaft)
    how = (
        f"Records: simulated series bench of the catalogue shaft {a.diameter_mm:g} x "
        f"{a.length_mm:g} mm, bends {', '.join(f'{b:g}' for b in model.bends_deg)} deg, "
        f"{hysteresis_id.DEFAULT_CHIRP_S:g} s chirp {hysteresis_id.DEFAULT_F_START_HZ:g}-"
        f"{hysteresis_id.DEFAULT_F_STOP_HZ:g} Hz at 0.8 x rating."
    )
    text = hysteresis_id.fractions_toml(model, shaft, how)
    print(text)
    print(f"identified in {time.perf_counter() - t0:.1f} s; values: {model.as_dict()}")
    if a.write:
        DATA.write_text(text, "utf-8")
        print(f"written: {DATA}")


if __name__ == "__main__":
    main()
