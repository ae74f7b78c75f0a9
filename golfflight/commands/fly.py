"""`golfflight fly`: fly one shot through the reference world and print its flight."""

from __future__ import annotations

import argparse
import json

import numpy as np

from flight.air import Air
from flight.constants import YARD_M
from flight.physics import initial_state
from flight.wind import Wind
from shots.clubs import CLUBS
from shots.reference_world import fly_reference


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("fly", help="fly one shot through the reference world (a club's typical launch or your own)")
    parser.add_argument("--club", choices=[c.name for c in CLUBS], default="Driver", help="start from this club's tour-average launch")
    parser.add_argument("--ball-speed-mps", type=float)
    parser.add_argument("--launch-angle-deg", type=float)
    parser.add_argument("--launch-direction-deg", type=float, default=0.0, help="+ = right of the target line")
    parser.add_argument("--spin-rpm", type=float)
    parser.add_argument("--spin-axis-deg", type=float, default=0.0, help="+ = tilted right, the ball curves right")
    parser.add_argument("--temperature-c", type=float, default=25.0)
    parser.add_argument("--altitude-m", type=float, default=0.0)
    parser.add_argument("--humidity-pct", type=float, default=50.0)
    parser.add_argument("--wind-speed-mps", type=float, default=0.0)
    parser.add_argument("--wind-from-deg", type=float, default=0.0, help="0 = headwind, 90 = from the right, 180 = tailwind")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.set_defaults(run=run)


def fly_one(launch: dict[str, float], air: Air, wind: Wind) -> dict[str, float]:
    """The flight of one shot as a flat dict of SI values with yards alongside."""
    state = initial_state(**{k: np.array([v]) for k, v in launch.items()})
    flight = fly_reference(state, air, wind)
    if not flight.landed[0]:
        raise ValueError("the shot did not come down within the simulation time cap")
    return {
        "carry_m": float(flight.carry_m[0]),
        "carry_yd": float(flight.carry_m[0] / YARD_M),
        "lateral_m": float(flight.lateral_m[0]),
        "apex_m": float(flight.apex_m[0]),
        "apex_yd": float(flight.apex_m[0] / YARD_M),
        "flight_time_s": float(flight.flight_time_s[0]),
        "landing_angle_deg": float(flight.landing_angle_deg[0]),
        "landing_speed_mps": float(flight.landing_speed_mps[0]),
        "landing_spin_rpm": float(flight.landing_spin_rpm[0]),
    }


def run(args: argparse.Namespace) -> int:
    club = next(c for c in CLUBS if c.name == args.club)
    launch = {
        "ball_speed_mps": args.ball_speed_mps if args.ball_speed_mps is not None else club.ball_speed_mps,
        "launch_angle_deg": args.launch_angle_deg if args.launch_angle_deg is not None else club.launch_angle_deg,
        "launch_direction_deg": args.launch_direction_deg,
        "spin_rpm": args.spin_rpm if args.spin_rpm is not None else club.spin_rpm,
        "spin_axis_deg": args.spin_axis_deg,
    }
    air = Air.from_conditions(args.temperature_c, args.altitude_m, args.humidity_pct)
    result = fly_one(launch, air, Wind(args.wind_speed_mps, args.wind_from_deg))
    if args.json:
        print(json.dumps({"launch": launch, "flight": result}, indent=2))
        return 0
    print(f"{args.club}: " + ", ".join(f"{k} {v:g}" for k, v in launch.items()))
    for key, value in result.items():
        print(f"  {key:<20} {value:9.2f}")
    return 0
