"""Diagnose the real data sets (read from the shared folder, never copied) and render a summary for the docs.

python -m golfflight.discovery.real --out runs/discovery-real [--model DIR|reference] [--venue-air]
python -m golfflight.discovery.real --baseline-pairs --out runs/discovery-baseline [--model DIR|reference] [--only RE]

Sets: the outdoor, radar-tracked TrackMan driver shots (all balls, the held-out lines alone, and Premium only), the
PGA TOUR TrackMan trajectories of the Sentry 2022 (spin from the play-by-play) and the Sony Open 2022 (spin estimated
from the initial lift), each per event and per round, the TOUR Championship 2020's radar tee shots (launch, spin and
apex) of its trainable rounds and of its held-out rounds apart, and TrackMan's PGA TOUR 2023 averages (one row per
club). Each set says whether it is held out (`shots.heldout`: only the driver file's lines from 2943
and the TOUR Championship's rounds 3-4), trained on by `models/default`, or neither. A set whose source's air is known
(`shots.source_air`: the PGA table, the Sentry, the TOUR Championship) is flown in that air, as training flew it; the
others (the range sessions, the Sony Open) in the model's air. With --venue-air each set whose air is known is
diagnosed a second time with its air concealed (as `golfflight convert pbp`, which records no air, gives it), and
venue_air.md tabulates what each run says about air (`discovery.venue_air`).

With --baseline-pairs, one set is diagnosed against another as its baseline session (`golfflight diagnose NEW
--baseline BASELINE`, issue 54) instead (`baseline_pairs`): on the driver file's trained lines (before 2943; the
held-out lines are not read), the shots of one ball type, the ball column dropped, against those of another; and
the tour events one may train on (the Sentry, the Sony Open, East Lake's rounds 1-2; never its held-out rounds 3-4)
one against another, the new event's air concealed where it is known, so that a change of air can be named and
compared with the venue's. baseline_pairs.md tabulates what each pair names, its rivals and what the baseline cannot
teach; baseline_pairs.json holds each report's statement, headline, candidates and baseline account.
"""

from __future__ import annotations

import argparse
import json
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from golfflight.discovery import svg
from golfflight.discovery.diagnose import Diagnosis, diagnose
from golfflight.discovery.form import learn_form
from golfflight.discovery.locate import binned_means
from golfflight.discovery.model import FlightModel, load_model
from golfflight.discovery.outputs import write_diagnosis
from golfflight.discovery.recordings import LABELS, OBSERVABLES, Recordings, from_shot_set
from golfflight.flight.air import STANDARD_TEMPERATURE_C, Air
from golfflight.shots.files import write_text_atomic
from golfflight.shots.heldout import held_out_rounds, held_out_set, shot_round
from golfflight.shots.markdown import table
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.pbp import load_pbp
from golfflight.shots.records import ShotRecord, ShotSet
from golfflight.shots.reference_world import default_tour_averages_path, read_tour_averages
from golfflight.shots.source_air import KNOWN_AIR, SourceAir
from golfflight.shots.tourcast import load_tourcast
from golfflight.shots.trackman import load_trackman

TOURCAST = Path("real") / "pga_tourcast_trackman"
TRACKMAN = Path("real") / "trackman_driver_sessions" / "data.csv"
TOUR_CHAMPIONSHIP = TOURCAST / "pbp" / "pbp_2020_060_688.csv"

HELD_OUT = "held out"
TRAINED_ON = "trained on"
"""What a set is to `models/default` (`RealSet.use`); the others say which part was trained on, or 'not trained on'."""


def in_air(records: list[ShotRecord], air: SourceAir | None) -> list[ShotRecord]:
    """The records with their source's air in the condition columns (unchanged where the air is not known)."""
    return records if air is None else [r.model_copy(update=air.record_conditions()) for r in records]


def tour_averages(path: str | Path) -> ShotSet:
    """TrackMan's tour-averages table as canonical records: one straight shot per club, carry, apex, land angle."""
    records = [
        ShotRecord(
            shot_id=row.club,
            session="PGA TOUR 2023",
            club=row.club,
            ball_speed_mps=row.ball_speed_mps,
            launch_angle_deg=row.launch_angle_deg,
            launch_direction_deg=0.0,
            spin_rpm=row.spin_rpm,
            spin_axis_deg=0.0,
            carry_y_m=row.carry_m,
            apex_m=row.max_height_m,
            landing_angle_deg=row.land_angle_deg,
        )
        for row in read_tour_averages(path)
    ]
    return ShotSet(in_air(records, KNOWN_AIR["pga-2023-table"]))


@dataclass
class RealSet:
    """One real data set to diagnose."""

    key: str
    title: str
    recordings: Recordings
    caveat: str
    use: str = ""
    """What the set is to `models/default`: HELD_OUT (`shots.heldout`), TRAINED_ON, or which part was trained on."""


def real_sets(shared: Path) -> list[RealSet]:
    """Every real set, converted in memory by the project's loaders."""
    return driver_sets(shared) + tourcast_sets(shared) + tour_championship_sets(shared) + [averages_set()]


def driver_sets(shared: Path) -> list[RealSet]:
    """The TrackMan driver sessions: all balls, the held-out lines alone, and the Premium balls."""
    held = held_out_set(TRACKMAN)  # shot_id is the line number in the export
    assert held is not None, "the driver file's second half is held out (shots.heldout)"
    first = held.first_line
    split = f"lines 3 to {first - 1} trained on, {first} on held out"
    driver = load_trackman(shared / TRACKMAN, skip_bad_rows=True)
    premium = load_trackman(shared / TRACKMAN, balls=["Premium"], skip_bad_rows=True)
    unseen = [r for r in driver.records if held.holds(int(r.shot_id))]
    return [
        RealSet(
            "trackman_driver",
            "TrackMan driver shots, outdoor radar-tracked, all balls",
            from_shot_set(ShotSet(driver.records), source=str(shared / TRACKMAN)),
            "one session (no dates): the diagnosis holds out blocks of shots; ball types mixed; no air recorded",
            split,
        ),
        RealSet(
            "trackman_driver_heldout",
            f"TrackMan driver shots, outdoor radar-tracked, all balls, held-out lines (from {first})",
            from_shot_set(ShotSet(unseen), source=f"{shared / TRACKMAN} (lines from {first})"),
            "the lines no model was trained on (shots.heldout; the earlier ones may be): one session, the diagnosis "
            "holds out blocks of shots; ball types mixed; no air recorded",
            HELD_OUT,
        ),
        RealSet(
            "trackman_driver_premium",
            "TrackMan driver shots, outdoor radar-tracked, Premium balls",
            from_shot_set(ShotSet(premium.records), source=str(shared / TRACKMAN) + " (Premium)"),
            "one session (no dates): the diagnosis holds out blocks of shots; no air recorded",
            split,
        ),
    ]


@dataclass(frozen=True)
class TourcastEvent:
    """A PGA TOUR event's TrackMan trajectories: where they are, where the spin comes from, and the event's air."""

    key: str
    title: str
    trajectories: str
    pbp: str | None
    """The play-by-play file with the measured spin; None: the spin is estimated from the initial lift."""
    caveat: str
    air: SourceAir | None
    use: str


TOURCAST_EVENTS = (
    TourcastEvent(
        "sentry",
        "PGA TOUR Sentry 2022 (Kapalua)",
        "shot_trajectory_2021_016_656.csv",
        "pbp_2021_016_656.csv",
        "spin from the play-by-play; spin axis derived from the initial lift",
        KNOWN_AIR["sentry-2022"],
        TRAINED_ON,
    ),
    TourcastEvent(
        "sony",
        "PGA TOUR Sony Open 2022 (Waialae)",
        "shot_trajectory_2021_006_006.csv",
        None,
        "spin ESTIMATED from the initial lift (Ferguson C_L): spin and lift effects are circular here",
        None,
        "not trained on",
    ),
)


def tourcast_sets(shared: Path) -> list[RealSet]:
    """Each TrackMan-tracked tour event with its trajectories, all rounds and round by round."""
    sets = []
    for event in TOURCAST_EVENTS:
        trajectories = shared / TOURCAST / "shot_trajectory" / event.trajectories
        conversion = load_tourcast(
            trajectories,
            None if event.pbp is None else shared / TOURCAST / "pbp" / event.pbp,
            estimate_spin=event.pbp is None,
            sample_interval_s=0.1,
            skip_bad_rows=True,
        )
        records = ShotSet(in_air(conversion.records, event.air))
        whole = from_shot_set(records, conversion.trajectories, str(trajectories))
        air = f"in the event's air ({event.air.basis})" if event.air else "no air known: the model's air"
        caveat = f"{event.caveat}; {air}"
        every_way = "; every hole faces another way, so a round's wind is not one wind in the shot frame"
        sets.append(RealSet(event.key, f"{event.title}, all rounds", whole, caveat + every_way, event.use))
        for session in np.unique(whole.session):
            part = whole.subset(whole.session == session)
            title = f"{event.title}, round {session.split('-R')[-1]}"
            sets.append(RealSet(f"{event.key}_{session}", title, part, caveat, event.use))
    return sets


def averages_set() -> RealSet:
    """TrackMan's PGA TOUR 2023 averages, one row per club, in the table's air."""
    averages = default_tour_averages_path()
    return RealSet(
        "pga_2023_averages",
        "TrackMan PGA TOUR 2023 averages (12 clubs)",
        from_shot_set(tour_averages(averages), source=str(averages)),
        "averages over players, events and weather; straight shots; the diagnosis holds out one club at a time; "
        f"in the table's air ({KNOWN_AIR['pga-2023-table'].basis})",
        TRAINED_ON,
    )


def tour_championship_sets(shared: Path) -> list[RealSet]:
    """The TOUR Championship 2020's radar tee shots with an apex (launch, spin, apex; no spin axis, so no side), in
    the event's air: its trainable rounds (trained on) and its held-out rounds (`shots.heldout`) as two sets."""
    path = shared / TOUR_CHAMPIONSHIP
    held_rounds = held_out_rounds(path)
    assert held_rounds, "the TOUR Championship's last rounds are held out (shots.heldout)"
    air = KNOWN_AIR["tour-championship-2020"]
    shots = [r for r in load_pbp(path, skip_bad_rows=True).records if r.apex_m is not None]
    caveat = (
        f"radar tee shots: launch, spin, apex; no spin axis recorded (0), so no side; clubs not named (par 3s: "
        f"irons); in the event's air ({air.basis})"
    )
    sets = []
    for key, held_out, use in (("trained", False, TRAINED_ON), ("heldout", True, HELD_OUT)):
        part = [r for r in shots if (shot_round(r.shot_id) in held_rounds) == held_out]
        numbers = sorted({shot_round(r.shot_id) for r in part})
        span = f"{numbers[0]}-{numbers[-1]}" if len(numbers) > 1 else f"{numbers[0]}"
        sets.append(
            RealSet(
                f"tour_championship_{key}",
                f"TOUR Championship 2020 (East Lake), rounds {span}",
                from_shot_set(ShotSet(in_air(part, air)), source=f"{path} (rounds {span})"),
                caveat,
                use,
            )
        )
    return sets


def summary_row(item: RealSet, diagnosis: Diagnosis) -> list[str]:
    report = diagnosis.report
    stats = {o.name: o for o in report.located.observables}
    bias = ", ".join(
        f"{n.split('_')[0] if n != 'carry_x_m' else 'side'} {stats[n].bias:+.2f} ({stats[n].rms_ratio:.1f}x)"
        for n in ("carry_y_m", "carry_x_m", "apex_m", "flight_time_s", "landing_angle_deg")
        if n in stats
    )
    effects = (
        "; ".join(
            f"{e.name} "
            + ", ".join(
                f"{k} {v:.3g} ± {e.uncertainty.get(k, float('nan')):.2g}"
                for k, v in e.parameters.items()
                if k != "density_kg_m3"
            )
            for e in report.effects
        )
        or "-"
    )
    scatter = ", ".join(
        f"{n.split('_')[0] if n != 'carry_x_m' else 'side'} {s.ratio:.1f}" for n, s in report.model.scatter.items()
    )
    held = report.heldout
    fraction = "-" if held.explained_fraction is None or not report.systematic else f"{held.explained_fraction:.0%}"
    return [
        f"{item.title} ({item.use})" if item.use else item.title,
        str(report.n_shots),
        scatter or "-",
        bias,
        "yes" if report.systematic else "no",
        effects,
        f"{held.before_error:.2f} → {held.after_error:.2f}",
        fraction,
        f"{report.seconds:.1f}",
    ]


NO_AIR = "_no_air"
"""Key suffix of a set diagnosed with its known air concealed."""


def venue_ratio(recordings: Recordings) -> float | None:
    """The recordings' median air density over ICAO standard density (None where they carry no air)."""
    if recordings.density_kg_m3 is None:
        return None
    return float(np.median(recordings.density_kg_m3) / Air.standard().density_kg_m3)


def with_and_without_air(sets: list[RealSet]) -> list[RealSet]:
    """Each set, followed, where its air is known, by the same shots carrying no air (flown in the model's air)."""
    out = []
    for item in sets:
        out.append(item)
        if item.recordings.density_kg_m3 is not None:
            concealed = replace(item.recordings, density_kg_m3=None, kinematic_viscosity_m2_s=None)
            title, caveat = f"{item.title}, air concealed", f"{item.caveat}; its air concealed"
            out.append(RealSet(item.key + NO_AIR, title, concealed, caveat, item.use))
    return out


def venue_air_row(item: RealSet, diagnosis: Diagnosis, venue: float | None) -> list[str]:
    """What one run says about air, as markdown cells: whether the recordings carry it (and the venue's, `venue` x
    ICAO, where known), what is named, and air density against it where they carry none."""
    report, rival = diagnosis.report, diagnosis.report.air_rival
    given = venue_ratio(item.recordings)
    air = (
        f"given ({given:.3f} × ICAO)"
        if given is not None
        else f"not given (venue {venue:.3f} × ICAO)"
        if venue is not None
        else "not known"
    )
    named = summary_row(item, diagnosis)[5] if report.systematic else "– (not systematic)"
    if rival is None:
        against, verdict, separate = "–", "not compared (air given)" if given is not None else "not compared", "–"
    else:
        interval = f"{rival.difference_ci[0]:+.3f} to {rival.difference_ci[1]:+.3f}"
        against = (
            f"{rival.explanation}: {rival.ratio:.3f} ± {rival.ratio_sd:.3f} (as at {rival.equivalent_altitude_m:.0f} m "
            f"at {STANDARD_TEMPERATURE_C:.0f} °C)"
            + ("" if rival.named else f"; held-out {rival.heldout_error:.3f} vs {report.heldout.after_error:.3f}")
            + ("" if rival.named else f" ({interval})")
        )
        verdict = "named" if rival.named else "ruled out" if rival.separable else "inseparable rival"
        separate = "–" if rival.named else LABELS[rival.separating_measurement].split(" (")[0]
    cells = [f"{item.title} ({item.use})" if item.use else item.title, str(report.n_shots), air, named, against]
    return [cell.replace("|", "\\|") for cell in cells + [verdict, separate]]  # |v| in a learned term


def concealed_air(recordings: Recordings) -> Recordings:
    """The same shots carrying no air (flown in the model's air), as `golfflight convert pbp` gives them."""
    return replace(recordings, density_kg_m3=None, kinematic_viscosity_m2_s=None)


@dataclass
class BaselinePair:
    """A new set diagnosed against a baseline set (`golfflight diagnose NEW --baseline BASELINE`)."""

    key: str
    baseline_title: str
    baseline: Recordings
    new_title: str
    new: Recordings
    known: str
    """What is known to differ between the two (the question the pair asks)."""
    venue: float | None = None
    """The new set's venue air (x ICAO) where it is known but concealed from the diagnosis."""


def training_driver_balls(shared: Path) -> dict[str, list[ShotRecord]]:
    """The driver file's measured shots on its trained lines only (before the first held-out line; the held-out
    lines are not read), grouped by the "Ball" column, each record's ball dropped (the diagnosis is not told)."""
    held = held_out_set(TRACKMAN)
    assert held is not None, "the driver file's second half is held out (shots.heldout)"
    conversion = load_trackman(shared / TRACKMAN, lines=(1, held.first_line - 1), skip_bad_rows=True)
    balls: dict[str, list[ShotRecord]] = {}
    for record in conversion.records:
        assert int(record.shot_id) < held.first_line
        balls.setdefault(record.ball or "(blank)", []).append(record.model_copy(update={"ball": None}))
    return balls


def driver_ball_pairs(shared: Path) -> list[BaselinePair]:
    """The Premium shots of the driver file's trained lines as the baseline of each other ball type there, and the
    reverse: one session, one monitor, the ball changed (and whatever weather changed between the ball's blocks)."""
    balls = training_driver_balls(shared)
    held = held_out_set(TRACKMAN)
    lines = f"lines before {held.first_line}"

    def recordings(ball: str) -> Recordings:
        return from_shot_set(ShotSet(balls[ball]), source=f"{shared / TRACKMAN} ({ball}, {lines}, ball dropped)")

    pairs = []
    for other in sorted(set(balls) - {"Premium"}):
        slug = re.sub(r"\W+", "_", other.lower())
        for a, b, key in (
            ("Premium", other, f"driver_premium_to_{slug}"),
            (other, "Premium", f"driver_{slug}_to_premium"),
        ):
            pairs.append(
                BaselinePair(
                    key,
                    f"TrackMan driver, {a} ({lines})",
                    recordings(a),
                    f"TrackMan driver, {b} ({lines})",
                    recordings(b),
                    f"the ball ({a} → {b}; the ball column dropped), and any weather between the ball's blocks of "
                    "shots; no air recorded (the model's air for both)",
                )
            )
    return pairs


def tour_pairs(shared: Path) -> list[BaselinePair]:
    """The tour events one may train on, one as the baseline of another: the Sentry (its air given) against the Sony
    Open (no air known) and against East Lake's rounds 1-2 (air concealed), East Lake's rounds 1-2 (air given)
    against the Sentry (air concealed), and East Lake's round 1 against its round 2 (air given to both). East Lake's
    held-out rounds 3-4 are not used."""
    sets = {item.key: item for item in tourcast_sets(shared) + tour_championship_sets(shared)}
    sentry, sony, east_lake = sets["sentry"], sets["sony"], sets["tour_championship_trained"]
    assert {shot_round(s) for s in east_lake.recordings.shot_id} == {1, 2}
    rounds = {int(s.split("-R")[-1]): s for s in np.unique(east_lake.recordings.session)}
    r1, r2 = (east_lake.recordings.subset(east_lake.recordings.session == rounds[n]) for n in (1, 2))
    given, concealed = "air given", "air concealed"
    east = "TOUR Championship 2020 (East Lake), rounds 1-2"
    return [
        BaselinePair(
            "sentry_to_sony",
            f"{sentry.title} ({given})",
            sentry.recordings,
            f"{sony.title} (no air known)",
            sony.recordings,
            "venue, days and air (Kapalua → Waialae; Sony's air not recorded: the model's air); Sony's spin is "
            "estimated from its initial lift",
        ),
        BaselinePair(
            "sentry_to_east_lake",
            f"{sentry.title} ({given})",
            sentry.recordings,
            f"{east} ({concealed})",
            concealed_air(east_lake.recordings),
            "venue, year and air (Kapalua 0.951 → East Lake 0.912 × ICAO); East Lake records the apex only",
            venue_ratio(east_lake.recordings),
        ),
        BaselinePair(
            "east_lake_to_sentry",
            f"{east} ({given})",
            east_lake.recordings,
            f"{sentry.title} ({concealed})",
            concealed_air(sentry.recordings),
            "venue, year and air (East Lake 0.912 → Kapalua 0.951 × ICAO); the baseline records the apex only",
            venue_ratio(sentry.recordings),
        ),
        BaselinePair(
            "east_lake_r1_to_r2",
            "TOUR Championship 2020 (East Lake), round 1 (air given)",
            r1,
            "TOUR Championship 2020 (East Lake), round 2 (air given)",
            r2,
            "the day (same venue and air as recorded; the wind and the pins are not recorded); apex only",
        ),
    ]


def baseline_pairs(shared: Path) -> list[BaselinePair]:
    """Every baseline pair (`driver_ball_pairs`, `tour_pairs`)."""
    return driver_ball_pairs(shared) + tour_pairs(shared)


def _effect_words(report, digits: int = 3) -> str:
    parts = []
    for e in report.effects:
        values = ", ".join(
            f"{k} {v:.{digits}g} ± {e.uncertainty.get(k, float('nan')):.2g}"
            for k, v in e.parameters.items()
            if k != "density_kg_m3"
        )
        parts.append(f"{e.name} [{e.kind}] ({values})")
    if report.unlisted is not None:
        parts.append(f"unlisted ({report.unlisted.expression})")
    return " + ".join(parts) or "–"


RIVALS = 5
"""Candidates listed per pair (the best by score, the chosen among them)."""


def baseline_pair_row(pair: BaselinePair, diagnosis: Diagnosis) -> list[str]:
    """One pair's row: the two sets, what the baseline taught, what is named and its rivals, what it cannot teach."""
    report = diagnosis.report
    info, held = report.baseline, report.heldout
    assert info is not None
    stats = {o.name: o for o in report.located.observables}
    bias = ", ".join(
        f"{LABELS[n].split(' (')[0]} {stats[n].bias:+.2f} ({stats[n].rms_ratio:.1f}x)"
        for n in OBSERVABLES
        if n in stats
    )
    named = _effect_words(report) if report.systematic else "– (not systematic)"
    ranked = sorted(report.candidates, key=lambda c: c.score)[:RIVALS]
    rivals = "; ".join(f"{c.name} {c.heldout_error:.2f}" for c in ranked) or "–"
    rival = report.air_rival
    if rival is None:
        air = "–"
    else:
        verdict = "named" if rival.named else "ruled out" if rival.separable else "inseparable"
        air = f"{rival.ratio:.3f} ± {rival.ratio_sd:.3f} ({verdict}; held-out {rival.heldout_error:.2f})"
        if pair.venue is not None:
            air += f"; venue {pair.venue:.3f}"
    fraction = "" if held.explained_fraction is None or not report.systematic else f" ({held.explained_fraction:.0%})"
    cells = [
        pair.key,
        f"{pair.baseline_title}: {info.n_shots}",
        f"{pair.new_title}: {report.n_shots}",
        f"{info.heldout_error_before:.2f} → {info.heldout_error_after:.2f}",
        f"{info.outside_shots}",
        bias,
        named,
        f"{held.before_error:.2f} → {held.after_error:.2f}{fraction}",
        rivals,
        air,
        " / ".join(info.cannot_inform) or "–",
    ]
    return [cell.replace("|", "\\|") for cell in cells]


BASELINE_HEADER = [
    "pair",
    "baseline: shots",
    "new: shots",
    "baseline held-out error (as is → form)",
    "new shots outside it",
    "new against the formed model: bias (RMS/expected)",
    "named",
    "new held-out error (explained)",
    "best candidates (held-out error)",
    "air against it",
    "the baseline cannot teach",
]


def run_baseline_pairs(pairs: list[BaselinePair], model: FlightModel, out: Path, seed: int = 0) -> list[list[str]]:
    """Diagnose each pair's new set against its baseline; baseline_pairs.md, baseline_pairs.json and each report."""
    rows, details = [], {}
    for pair in pairs:
        form = learn_form(pair.baseline, model, seed=seed)
        diagnosis = diagnose(pair.new, model, seed=seed, progress=False, baseline=form)
        report = diagnosis.report
        write_diagnosis(diagnosis, out / pair.key)
        rows.append(baseline_pair_row(pair, diagnosis))
        details[pair.key] = {
            "baseline": pair.baseline_title,
            "new": pair.new_title,
            "known": pair.known,
            "venue": pair.venue,
            "statement": report.statement,
            "headline": report.headline,
            "baseline_info": None if report.baseline is None else report.baseline.model_dump(),
            "candidates": [
                {"name": c.name, "heldout_error": c.heldout_error, "score": c.score, "n_parameters": c.n_parameters,
                 "effects": [e.model_dump() for e in c.effects]}
                for c in sorted(report.candidates, key=lambda c: c.score)
            ],
            "ambiguities": [a.model_dump() for a in report.ambiguities],
            "air_rival": None if report.air_rival is None else report.air_rival.model_dump(),
            "heldout": report.heldout.model_dump(),
            "located": report.located.summary,
            "seconds": report.seconds,
        }
        print(f"{pair.key}: {' '.join(report.headline) or report.statement}", flush=True)
    lines = table(BASELINE_HEADER, rows, align="l" * len(BASELINE_HEADER))
    write_text_atomic(out / "baseline_pairs.md", f"Model: {model.name}\n\n" + "\n".join(lines) + "\n")
    write_text_atomic(out / "baseline_pairs.json", json.dumps(details, indent=1) + "\n")
    return rows


def figures(diagnosis: Diagnosis) -> dict[str, str]:
    """Aggregate plots only (binned means, histograms: no individual shot of the real data): name -> SVG."""
    rec = diagnosis.recordings
    out = {}
    speed = rec.launch["ball_speed_mps"]
    trend = []
    for j, name in enumerate(OBSERVABLES):
        if name not in rec.observed_names:
            continue
        x, y = binned_means(speed, rec.observed[:, j] - diagnosis.before[:, j])
        scale = diagnosis.report.heldout.expected[name]
        trend.append((x, y / scale, name, j, False))
    out["residual_vs_speed"] = svg.lines(
        "mean residual / expected sigma vs ball speed (model as is)", "ball speed (m/s)", "residual / sigma", trend
    )
    for j, name in enumerate(OBSERVABLES):
        if name not in ("carry_y_m", "landing_angle_deg") or name not in rec.observed_names:
            continue
        series = [(diagnosis.heldout_before[:, j], "held out, model as is")]
        if diagnosis.chosen is not None:
            series.append((diagnosis.heldout_after[:, j], "held out, corrected"))
        out[f"heldout_{name}"] = svg.histogram(f"held-out residual: {name}", LABELS[name], series)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="folder for one report folder per set and summary.md")
    parser.add_argument("--model", help="bundle directory or 'reference' (default: models/default)")
    parser.add_argument("--only", help="regular expression on the set keys")
    parser.add_argument("--figures", help="folder for aggregate SVG figures of each set (e.g. docs/discovery)")
    parser.add_argument(
        "--venue-air", action="store_true", help="also diagnose each set of known air without it; venue_air.md"
    )
    parser.add_argument(
        "--baseline-pairs",
        action="store_true",
        help="instead, diagnose sets against others as their baseline session (ball types of the driver file's "
        "trained lines, the trainable tour events); baseline_pairs.md (--only filters the pair keys)",
    )
    args = parser.parse_args(argv)
    model: FlightModel = load_model(args.model)
    out = Path(args.out)
    if args.baseline_pairs:
        pairs = [p for p in baseline_pairs(shared_data_dir()) if not args.only or re.search(args.only, p.key)]
        run_baseline_pairs(pairs, model, out)
        return 0
    rows, details, air_rows = [], {}, []
    sets = real_sets(shared_data_dir())
    venue = {item.key + NO_AIR: venue_ratio(item.recordings) for item in sets}
    for item in with_and_without_air(sets) if args.venue_air else sets:
        if args.only and not re.search(args.only, item.key):
            continue
        diagnosis = diagnose(item.recordings, model)
        write_diagnosis(diagnosis, out / item.key)
        if args.figures:
            for name, text in figures(diagnosis).items():
                write_text_atomic(Path(args.figures) / f"{item.key}_{name}.svg", text)
        rows.append(summary_row(item, diagnosis))
        air_rows.append(venue_air_row(item, diagnosis, venue.get(item.key)))
        rival = diagnosis.report.air_rival
        details[item.key] = {
            "title": item.title,
            "use": item.use,
            "caveat": item.caveat,
            "statement": diagnosis.report.statement,
            "located": diagnosis.report.located.summary,
            "ambiguities": [a.note for a in diagnosis.report.ambiguities],
            "air_rival": None if rival is None else rival.model_dump(),
        }
        print(f"{item.key}: {diagnosis.report.statement}", flush=True)
    header = [
        "set",
        "shots",
        "scatter (x assumed noise)",
        "bias (RMS/expected)",
        "systematic",
        "named",
        "held-out error",
        "excess removed",
        "s",
    ]
    lines = table(header, rows, align="l" * len(header))
    write_text_atomic(out / "summary.md", f"Model: {model.name}\n\n" + "\n".join(lines) + "\n")
    write_text_atomic(out / "details.json", json.dumps(details, indent=1) + "\n")
    if args.venue_air:
        header = ["set", "shots", "air", "named", "air density against it", "air is", "would separate them"]
        lines = table(header, air_rows, align="l" * len(header))
        write_text_atomic(out / "venue_air.md", f"Model: {model.name}\n\n" + "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
