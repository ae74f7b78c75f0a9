"""Issue 41's new campaigns at a commit that predates them: the six pairs of `prove --campaign pairs` (in the
served model's own flights) and the clean and library sets of `prove --truth ferguson`, concealed and diagnosed by
the checkout this script is run in, so that the tables of docs/discovery.md have a "before".

    git worktree add /tmp/before 90503c4 && cd /tmp/before && python - --out FILE.json < /path/to/scripts/prove_before.py

(read from standard input, so that the checkout in the current folder is the one imported, not an installed one).

It uses only what that commit already had (`prove.run_case`, `prove.draw_effect`, `conceal`, `diagnose`), with the
pairs and the Ferguson world spelled out here as `prove.PAIRS` and `prove.ferguson_world` spell them now; the output
is the runs' JSON in `prove.Run`'s fields that both commits share, which `prove --tables-from` does not read back (the
summary it prints is what the docs quote).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from golfflight.discovery.conceal import NOMINAL_AIR, conceal
from golfflight.discovery.diagnose import diagnose
from golfflight.discovery.effects import LIBRARY
from golfflight.discovery.model import MIN_T_MAX_S, FlightModel, load_model
from golfflight.discovery.prove import draw_effect, relative_error, run_case
from golfflight.discovery.recordings import from_shot_set
from golfflight.flight.coefficients import QuadraticSpinRatio
from golfflight.flight.flyer import FixedCoefficients, Flyer
from golfflight.flight.integrator import RUNGE_KUTTA_4

PAIRS = (
    ("wind", "ball_speed_bias"),
    ("air_density", "launch_angle_bias"),
    ("landing_elevation", "spin_axis_bias"),
    ("spin_bias", "lift_scale"),
    ("drag_scale", "launch_direction_bias"),
    ("wind", "spin_bias"),
)
ACTED_ON = {"wind", "air_density", "landing_elevation"} | {e.name for e in LIBRARY if e.name.endswith("_bias")}
"""Venue conditions and monitor biases (the effects' kinds, which the older commit does not have)."""


def ferguson() -> FlightModel:
    """Ferguson 2022's coefficients as a world: RK4 at 0.01 s in ICAO air."""
    flyer = Flyer(
        FixedCoefficients(QuadraticSpinRatio()),
        dt_s=0.01,
        max_flight_time_s=MIN_T_MAX_S,
        density_kg_m3=float(NOMINAL_AIR.density_kg_m3),
        kinematic_viscosity_m2_s=float(NOMINAL_AIR.kinematic_viscosity_m2_s),
        rule=RUNGE_KUTTA_4,
    )
    return FlightModel("Ferguson 2022 (RK4, dt 0.01 s)", flyer)


def ferguson_run(model: FlightModel, world: FlightModel, effects: tuple[str, ...], seed: int) -> dict:
    """One Ferguson-world set as `prove.run_case` draws and scores it."""
    rng = np.random.default_rng(10_000 + seed)
    hidden = {name: draw_effect(name, rng) for name in effects}
    report = diagnose(from_shot_set(conceal(hidden, 300, seed, model=world).shots), model, seed=seed, progress=False)
    report = report.report
    fitted = {e.name: dict(e.parameters) for e in report.effects} if report.systematic else {}
    errors = {name: relative_error(name, fitted[name], hidden[name]) for name in hidden if name in fitted}
    return {"case": "+".join(effects) or "clean", "seed": seed, "systematic": report.systematic,
            "named": sorted(fitted), "parameter_error": errors}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    model, runs, started = load_model(None), [], time.perf_counter()
    for pair in PAIRS:
        for seed in range(2):
            run = run_case(model, "+".join(pair), pair, seed, 300, "model")
            within = set(run.parameter_error) == set(pair) and all(e <= 0.1 for e in run.parameter_error.values())
            runs.append({"case": run.case, "seed": seed, "named": sorted(run.fitted), "within": within})
    world = ferguson()
    plan = [((), seed) for seed in range(40)] + [((e.name,), seed) for e in LIBRARY for seed in range(4)]
    runs += [ferguson_run(model, world, effects, seed) for effects, seed in plan]
    pairs = [r for r in runs if "within" in r]
    clean = [r for r in runs if r["case"] == "clean"]
    hidden = [r for r in runs if "within" not in r and r["case"] != "clean"]
    print(f"pairs, both named and within 10 %: {sum(r['within'] for r in pairs)} of {len(pairs)}")
    print(f"Ferguson clean sets naming no venue or monitor condition: "
          f"{sum(not (r['systematic'] and ACTED_ON & set(r['named'])) for r in clean)} of {len(clean)}")
    good = [r for r in hidden if r["case"] in r["parameter_error"] and r["parameter_error"][r["case"]] <= 0.1]
    print(f"Ferguson hidden library effect named within 10 %: {len(good)} of {len(hidden)}")
    print(f"({time.perf_counter() - started:.0f} s)")
    with open(args.out, "w") as handle:
        json.dump(runs, handle, indent=1)


if __name__ == "__main__":
    main()
