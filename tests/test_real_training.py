"""Learning from real flights: the training set never holds held-out rows, latent winds are recovered, the joint
loss falls, and the shipped model's card names its sources and held-out sets."""

from __future__ import annotations

import copy
import csv
import json
from pathlib import Path

import numpy as np
import pytest
import torch
from conftest import trainable_copy
from golfflight.flight.physics import initial_state
from golfflight.model_export.joint import JointConfig, LatentConditions, cosine_factor, soup_runs, train_joint
from golfflight.model_export.observations import load_observed
from golfflight.model_export.real_data import (
    BUILDERS,
    DRIVER_FILE,
    PLAYERS_PBP,
    build,
    driver_groups,
    players,
    trackman_outdoor,
)
from golfflight.flight.rollout import euler_rollout, hard_landing, positions_at
from golfflight.model_export.training import load_checkpoint
from golfflight.model_export.variants import PhysNN, PhysQ
from golfflight.shots.heldout import (
    HELD_OUT,
    HeldOutError,
    HeldOutSet,
    check_training_rows,
    held_out_rounds,
    held_out_set,
    shot_round,
)
from golfflight.shots.paths import REPO_ROOT, shared_data_dir
from golfflight.shots.records import ShotRecord, read_shots, trajectories_path, write_shots, write_trajectories
from golfflight.weights_schema.bundle import load_bundle

torch.set_num_threads(1)
FIXTURE = Path(__file__).parent / "fixtures" / "trackman_export.csv"


def _driver_file(root: Path, measured_lines: list[int], n_lines: int = 2950) -> Path:
    """A TrackMan export of `n_lines` lines (header and units rows, then shots) laid out like the shared driver
    file; the shots on `measured_lines` are measured outdoor flights, every other one an indoor row."""
    with FIXTURE.open(newline="") as handle:
        header, units, shot = list(csv.reader(handle))[:3]
    last_point = header.index("Last data Point - Time")
    indoor = list(shot)
    indoor[last_point] = "0.3"
    path = root / DRIVER_FILE
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerows([header, units])
        writer.writerows(shot if line in measured_lines else indoor for line in range(3, n_lines + 1))
    return path


TOUR_CHAMPIONSHIP = "real/pga_tourcast_trackman/pbp/pbp_2020_060_688.csv"
PGA_TABLE = "reference/trackman_tour_averages_pga_2023.csv"


def test_the_registry_holds_the_driver_files_second_half_and_tour_championship_rounds_3_4():
    assert {held.path.name for held in HELD_OUT} == {"data.csv", "pbp_2020_060_688.csv"}
    assert held_out_set("/anywhere/real/trackman_driver_sessions/data.csv").first_line == 2943
    tour = held_out_set(f"/anywhere/{TOUR_CHAMPIONSHIP}")
    assert tour.rounds == (3, 4) and tour.rows() == "rounds 3-4" and not tour.whole
    assert held_out_rounds(f"/anywhere/{TOUR_CHAMPIONSHIP}") == (3, 4)
    assert held_out_rounds("/anywhere/real/trackman_driver_sessions/data.csv") == ()
    assert held_out_set(f"/anywhere/{PGA_TABLE}") is None, "the PGA 2023 table may be trained on (shots.heldout)"


def test_a_held_out_line_refuses_the_training_set(tmp_path):
    path = tmp_path / "real" / "trackman_driver_sessions" / "data.csv"
    check_training_rows(path, [3, 2942])
    check_training_rows(path, shot_ids=["trackman-outdoor:2942", "17"])
    with pytest.raises(HeldOutError, match="lines 2943"):
        check_training_rows(path, [2941, 2943])
    with pytest.raises(HeldOutError, match="trackman-outdoor:2943"):
        check_training_rows(path, shot_ids=["trackman-outdoor:2943"])
    check_training_rows(tmp_path / "real/pga_tourcast_trackman/pbp/pbp_2021_016_656.csv", [2])
    check_training_rows(tmp_path / PGA_TABLE, [])


def test_a_shot_of_a_held_out_round_refuses_the_training_set(tmp_path):
    """Canonical tour ids ('060-R3-H15-P29725-S1', also behind a source prefix) name their round: rounds 3-4 of the
    TOUR Championship are refused, rounds 1-2 and the file itself pass."""
    path = tmp_path / TOUR_CHAMPIONSHIP
    assert shot_round("060-R3-H15-P29725-S1") == 3
    assert shot_round("tour-championship-2020:060-R1-H2-P11111-S1-f2") == 1
    with pytest.raises(ValueError):
        shot_round("tour-championship-2020:2943")
    check_training_rows(path)
    check_training_rows(path, [])
    check_training_rows(path, shot_ids=["060-R1-H2-P11111-S1", "tour-championship-2020:060-R2-H15-P22222-S1-f1"])
    for leaked in ("060-R3-H15-P29725-S1", "tour-championship-2020:060-R4-H1-P11111-S1", "not-a-tour-id"):
        with pytest.raises(HeldOutError, match="rounds 3-4"):
            check_training_rows(path, shot_ids=["060-R1-H1-P11111-S1", leaked])


def test_a_held_out_rounds_lines_are_found_through_the_round_column(tmp_path):
    """Lines of a file split by rounds are refused by the round their row names; unreadable rounds refuse too."""
    path = tmp_path / TOUR_CHAMPIONSHIP
    with pytest.raises(HeldOutError, match="cannot be read"):
        check_training_rows(path, [2])
    path.parent.mkdir(parents=True)
    path.write_text("roundNumber,holeNumber\n1,1\n3,1\n2,5\n")
    check_training_rows(path, [2, 4])
    with pytest.raises(HeldOutError, match="1 held-out lines .* 3$"):
        check_training_rows(path, [2, 3, 4])
    with pytest.raises(HeldOutError, match="5$"):
        check_training_rows(path, [5])


def test_a_file_held_out_whole_refuses_any_use(tmp_path, monkeypatch):
    import golfflight.shots.heldout

    whole = HeldOutSet("a whole file", Path("real/whole.csv"))
    monkeypatch.setattr(golfflight.shots.heldout, "HELD_OUT", (*HELD_OUT, whole))
    assert whole.whole and whole.holds(2) and whole.holds_round(1) and whole.rows() == "all"
    with pytest.raises(HeldOutError, match="whole file"):
        check_training_rows(tmp_path / "real" / "whole.csv", [])


def test_the_trainable_copy_of_a_data_folder_holds_no_held_out_row(tmp_path):
    """`conftest.trainable_copy` on a hand-made folder: the driver file cut before line 2943, the TOUR Championship
    less rounds 3-4, every other file as it was."""
    root = tmp_path / "shared"
    driver = root / "real" / "trackman_driver_sessions" / "data.csv"
    driver.parent.mkdir(parents=True)
    driver.write_text("".join(f"{line},x\n" for line in range(1, 2951)))
    tour = root / TOUR_CHAMPIONSHIP
    tour.parent.mkdir(parents=True)
    tour.write_text("roundNumber,holeNumber\n1,1\n3,2\n2,3\n4,4\n")
    (root / PGA_TABLE).parent.mkdir(parents=True)
    (root / PGA_TABLE).write_text("club\nDriver\n")
    copy = trainable_copy(root, tmp_path / "copy")
    lines = (copy / driver.relative_to(root)).read_text().splitlines()
    assert len(lines) == 2942 and lines[-1] == "2942,x"
    assert (copy / TOUR_CHAMPIONSHIP).read_text().splitlines() == ["roundNumber,holeNumber", "1,1", "2,3"]
    assert (copy / PGA_TABLE).read_text() == "club\nDriver\n"


def test_driver_training_shots_stop_at_line_2942(tmp_path):
    _driver_file(tmp_path, measured_lines=[10, 11, 12, 2941, 2942, 2943, 2944, 2950])
    data = trackman_outdoor(tmp_path)
    lines = sorted(int(r.shot_id.split(":")[1]) for r in data.records)
    assert lines == [10, 11, 12, 2941, 2942]
    assert {r.source for r in data.records} == {"trackman-outdoor"}


def test_driver_groups_are_runs_of_nearby_lines_of_one_ball():
    def shot(line: int, ball: str) -> ShotRecord:
        return ShotRecord(shot_id=str(line), ball=ball, ball_speed_mps=60, launch_angle_deg=12,
                          launch_direction_deg=0, spin_rpm=2500, spin_axis_deg=0)

    records = [shot(3, "Premium"), shot(4, "Premium"), shot(6, "Premium"), shot(20, "Premium"), shot(21, "Soft")]
    assert driver_groups(records) == ["L3", "L3", "L3", "L20", "L21"]


def test_players_shots_train_on_the_carry_their_apex_range_records(tmp_path):
    fixture = Path(__file__).parent / "fixtures" / "pbp.csv"
    with fixture.open(newline="") as handle:
        rows = [{**r, "seasonYear": "2020", "tournamentNumber": "011", "radarData.horizontalLaunchAngle": "1.0"}
                for r in csv.DictReader(handle) if r["radarData.verticalLaunchAngle"] != "high"]
    path = tmp_path / PLAYERS_PBP
    path.parent.mkdir(parents=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    data = players(tmp_path)
    first = next(r for r in data.records if r.shot_id == "players-2020:011-R1-H1-P11111-S1")
    range_m, side_m = 520.5 * 0.3048, -12.5 * 0.3048
    assert first.carry_y_m == pytest.approx(np.sqrt(range_m**2 - side_m**2))
    assert first.carry_x_m is None and first.apex_m is None and first.flight_time_s is None
    assert {r.source for r in data.records} == {"players-2020"}
    assert {r.split for r in data.records if r.group.endswith("-H4")} == {"val"}
    assert {r.split for r in data.records if not r.group.endswith("-H4")} == {"train"}


REAL_SOURCES = tuple(name for name in BUILDERS if name != "synthetic")
"""Every source read from the shared data folder."""
needs_shared_data = pytest.mark.skipif(not (shared_data_dir() / DRIVER_FILE).is_file(),
                                       reason="shared data not present")


@needs_shared_data
def test_the_merged_real_training_file_holds_no_held_out_row(tmp_path):
    built = build(shared_data_dir(), tmp_path / "real.csv", REAL_SOURCES)
    shots = read_shots(tmp_path / "real.csv")
    ids, sources = list(shots.column("shot_id")), list(shots.column("source"))
    driver_lines = [int(s.split(":")[1]) for s, src in zip(ids, sources) if src.startswith("trackman")]
    assert driver_lines and max(driver_lines) <= 2942
    tour = [shot_round(s) for s in ids if s.startswith("tour-championship-2020:")]
    assert set(tour) <= {1, 2}, "a TOUR Championship round 3-4 shot reached training or validation"
    for data in built:
        for path in data.files:
            check_training_rows(shared_data_dir() / path, shot_ids=[r.shot_id for r in data.records])
            assert held_out_set(path) is None or not held_out_set(path).whole
    splits = {}
    for group, split in zip(shots.column("group"), shots.column("split")):
        splits.setdefault(group, set()).add(split)
    assert all(len(s) == 1 for s in splits.values()), "a conditions group spans train and validation"


@needs_shared_data
def test_held_out_rows_change_nothing_in_the_real_training_set(tmp_path):
    """Built from the shared folder and from a copy without a single held-out row, the merged file (every record,
    its group and its train or validation split) and its trajectories are the same: no held-out row reaches
    training, validation or a choice the builders make."""
    build(shared_data_dir(), tmp_path / "all.csv", REAL_SOURCES)
    build(trainable_copy(shared_data_dir(), tmp_path / "trainable"), tmp_path / "trainable.csv", REAL_SOURCES)
    assert (tmp_path / "all.csv").read_text() == (tmp_path / "trainable.csv").read_text()
    assert trajectories_path(tmp_path / "all.csv").read_text() == trajectories_path(
        tmp_path / "trainable.csv").read_text()


def test_positions_at_interpolates_between_euler_steps():
    position = torch.zeros(1, 3)
    velocity = torch.tensor([[0.0, 10.0, 0.0]])
    trajectory = euler_rollout(position, velocity, torch.zeros(1, 3), lambda v, w: torch.zeros(1, 4), 1.2, 0.1, 1.0)
    got = positions_at(trajectory, torch.tensor([[0.25, 0.5]]))
    np.testing.assert_allclose(got[0, :, 1].numpy(), [2.5, 5.0], atol=1e-5)


def _windy_set(path: Path, winds: dict[str, tuple[float, float]], n_per_group: int = 24) -> None:
    """Shots flown in torch through Ferguson's coefficients, each group (a hole of one round: one air group) in its
    own uniform wind, with paths."""
    rng = np.random.default_rng(3)
    records, paths = [], {}
    model = PhysQ()
    for g, (wx, wy) in winds.items():
        launch = {"ball_speed_mps": rng.uniform(55, 70, n_per_group), "launch_angle_deg": rng.uniform(10, 15, n_per_group),
                  "launch_direction_deg": np.zeros(n_per_group), "spin_rpm": rng.uniform(2200, 3200, n_per_group),
                  "spin_axis_deg": np.zeros(n_per_group)}
        state = initial_state(**launch)
        tensor = lambda a: torch.as_tensor(a, dtype=torch.float32)  # noqa: E731
        wind = torch.tensor([[wx, wy, 0.0]]).expand(n_per_group, 3)
        with torch.no_grad():
            trajectory = euler_rollout(tensor(state.position), tensor(state.velocity), tensor(state.spin), model,
                                       1.225, wind=wind)
            landing = hard_landing(trajectory)
            times = torch.arange(1, 9, dtype=torch.float32).expand(n_per_group, 8) * 0.5
            sampled = positions_at(trajectory, times) - trajectory.positions[0][:, None]
        for i in range(n_per_group):
            shot_id = f"{g}-{i}"
            records.append(ShotRecord(
                shot_id=shot_id, source="sentry-2022", group=g, split="train",
                **{k: float(v[i]) for k, v in launch.items()},
                carry_x_m=float(landing.position[i, 0]), carry_y_m=float(landing.position[i, 1]),
                apex_m=float(trajectory.apex_m[i])))
            paths[shot_id] = np.column_stack([times[i].numpy(), sampled[i].numpy()])
    records.append(records[0].model_copy(update={"shot_id": "val-0", "group": "val", "split": "val"}))
    write_shots(path, records)
    write_trajectories(trajectories_path(path), paths)


def test_a_latent_wind_is_recovered_from_flights_in_a_known_wind(tmp_path):
    winds = {"016-R1-H1": (0.0, -3.0), "016-R1-H2": (0.0, 3.0), "016-R1-H3": (2.5, 0.0), "016-R1-H4": (-2.5, 0.0)}
    _windy_set(tmp_path / "windy.csv", winds)
    model = PhysQ()
    config = JointConfig(epochs=15, batch_size=32, lr=0.0, latent_lr=0.2, weights={"sentry-2022": 1.0})
    train_joint(tmp_path / "windy.csv", tmp_path / "run", config, model, progress=False)
    fitted = torch.load(tmp_path / "run" / "last.pt", weights_only=True)["latent"]["wind"].numpy()
    for group, truth in zip(load_observed(tmp_path / "windy.csv", config.weights).wind_groups.names, fitted):
        np.testing.assert_allclose(truth, winds[group], atol=0.35, err_msg=group)
    assert json.loads((tmp_path / "run" / "conditions.json").read_text())["wind"][0]["group"] == "016-R1-H1"


def test_the_latent_prior_pulls_each_sources_mean_wind_to_calm(tmp_path):
    _windy_set(tmp_path / "windy.csv", {"a": (0.0, 0.0), "b": (0.0, 0.0)}, n_per_group=4)
    data = load_observed(tmp_path / "windy.csv", {"sentry-2022": 1.0})
    latent = LatentConditions(data)
    source = torch.zeros(len(data.wind_groups), dtype=torch.long)
    air = torch.zeros(len(data.air_groups), dtype=torch.long)
    with torch.no_grad():
        latent.wind[:] = torch.tensor([[1.0, 0.0], [-1.0, 0.0]])
        balanced = latent.prior(JointConfig(), source, air, data.sources)
        latent.wind[:] = torch.tensor([[1.0, 0.0], [1.0, 0.0]])
        shifted = latent.prior(JointConfig(), source, air, data.sources)
    assert float(shifted) > float(balanced) + 5


def test_a_tiny_joint_run_lowers_its_loss(tmp_path):
    _windy_set(tmp_path / "windy.csv", {"a": (0.0, 1.0), "b": (1.0, 0.0)}, n_per_group=16)
    torch.manual_seed(0)
    model = PhysNN("phys-nn+", (8,))
    result = train_joint(tmp_path / "windy.csv", tmp_path / "run", JointConfig(epochs=6, batch_size=16, lr=3e-3),
                         model, progress=False)
    losses = [row["train_loss"] for row in result.history]
    assert losses[-1] < 0.8 * losses[0]
    assert (tmp_path / "run" / "last.pt").is_file()


def test_the_soup_of_seeds_is_their_mean_weights_scored_like_a_run(tmp_path):
    _windy_set(tmp_path / "windy.csv", {"a": (0.0, 1.0), "b": (1.0, 0.0)}, n_per_group=8)
    torch.manual_seed(0)
    start = PhysNN("phys-nn+", (8,))
    runs = [train_joint(tmp_path / "windy.csv", tmp_path / f"seed-{seed}",
                        JointConfig(epochs=2, batch_size=4, lr=3e-3, seed=seed), copy.deepcopy(start), progress=False)
            for seed in (0, 1)]
    soup_runs(tmp_path / "windy.csv", [r.out_dir for r in runs], tmp_path / "soup", copy.deepcopy(start))
    seeds = [load_checkpoint(r.out_dir / "last.pt")["model"] for r in runs]
    souped = load_checkpoint(tmp_path / "soup" / "last.pt")["model"]
    assert any(not torch.equal(seeds[0][name], seeds[1][name]) for name in souped)
    for name, weight in souped.items():
        torch.testing.assert_close(weight, (seeds[0][name] + seeds[1][name]) / 2)
    assert json.loads((tmp_path / "soup" / "conditions.json").read_text())["wind"]
    alone = soup_runs(tmp_path / "windy.csv", [runs[0].out_dir], tmp_path / "alone", copy.deepcopy(start))
    assert alone.final["val_loss"] == pytest.approx(runs[0].final["val_loss"], rel=1e-5)


REAL = REPO_ROOT / "models" / "real"


def test_the_real_data_card_names_its_sources_with_hashes_and_its_held_out_errors():
    card, _ = load_bundle(REAL)
    sources = card.training_data.sources
    assert sources, "models/real was not trained on real flights"
    kinds = {s.name: s.kind for s in sources}
    assert kinds["trackman-outdoor"] == "measured" and kinds["synthetic"] == "synthetic"
    for source in sources:
        for f in source.files:
            held = held_out_set(f.path)
            assert held is None or not held.whole, f"{f.path} is held out whole"
    held_out = {h.name: h for h in card.held_out or []}
    assert {h.name for h in HELD_OUT} <= set(held_out)
    assert all(h.errors for h in held_out.values())
    assert (REAL / "training_conditions.json").is_file()


def test_the_learning_rate_decays_along_half_a_cosine():
    assert cosine_factor(0, 101, 0.1) == 1.0
    assert cosine_factor(50, 101, 0.1) == pytest.approx(0.1 + 0.9 * 0.5)
    assert cosine_factor(100, 101, 0.1) == pytest.approx(0.1)
