"""The trainable sources the revised rule opened (`shots.heldout`): the PGA 2023 table as one shot per club in its
air, the TOUR Championship's rounds 1-2 in East Lake's air; the known-air sources setting the level in the joint
prior; and the felt error that compares runs."""

from __future__ import annotations

import pytest
import torch
from golfflight.flight.constants import YARD_M
from golfflight.model_export.joint import JointConfig, LatentConditions, felt_error_m, selection_loss
from golfflight.model_export.real_data import TABLE_VAL_EVERY, pga_table, tour_championship
from golfflight.shots.paths import shared_data_dir
from golfflight.shots.records import ShotSet
from golfflight.shots.source_air import KNOWN_AIR

ROOT = shared_data_dir()


def _needs(path: str) -> None:
    if not (ROOT / path).exists():
        pytest.skip(f"shared data not found at {ROOT / path}")


def test_the_pga_table_is_one_average_shot_per_club_in_its_air():
    _needs("reference/trackman_tour_averages_pga_2023.csv")
    data = pga_table(ROOT)
    assert len(data.records) == 12 and data.kind == "measured"
    driver = next(r for r in data.records if r.club == "Driver")
    assert driver.carry_y_m == pytest.approx(282 * YARD_M) and driver.apex_m == pytest.approx(35 * YARD_M)
    assert driver.ball_speed_mps == pytest.approx(171 * 0.44704) and driver.spin_axis_deg == 0.0
    assert [r.club for r in data.records if r.split == "val"] == ["3-wood", "3-iron", "6-iron", "9-iron"]
    assert TABLE_VAL_EVERY == 3
    density = ShotSet(data.records).air().density_kg_m3
    assert density == pytest.approx(KNOWN_AIR["pga-2023-table"].air().density_kg_m3)


def test_the_tour_championship_trains_on_rounds_one_and_two_in_east_lakes_air():
    _needs("real/pga_tourcast_trackman/pbp/pbp_2020_060_688.csv")
    data = tour_championship(ROOT)
    rounds = {r.shot_id.split(":")[1].split("-")[1] for r in data.records}
    assert rounds == {"R1", "R2"}
    assert all(r.apex_m is not None and r.carry_y_m is None for r in data.records)
    assert len(data.records) > 900
    holes = {int(r.group.rsplit("-H", 1)[1]) for r in data.records if r.split == "val"}
    assert holes and all(h % 4 == 0 for h in holes)
    density = ShotSet(data.records[:5]).air().density_kg_m3
    assert density == pytest.approx(KNOWN_AIR["tour-championship-2020"].air().density_kg_m3)


def test_felt_error_counts_a_bias_twice_and_scatter_once():
    biased = {"carry_y_m_mae": 8.0, "carry_y_m_bias": -8.0}
    scattered = {"carry_y_m_mae": 10.0, "carry_y_m_bias": 0.0}
    assert felt_error_m(biased) == 16.0 and felt_error_m(scattered) == 10.0
    assert felt_error_m({"apex_m_mae": 1.0, "apex_m_bias": 0.5}) == 1.5
    metrics = {"sources": {"a": biased, "b": scattered, "synthetic": {"carry_y_m_mae": 100.0, "carry_y_m_bias": 0.0}}}
    assert selection_loss(metrics, JointConfig(select_on=("a", "b"))) == 13.0


class _Data:
    """Just what LatentConditions reads: the sizes of its families."""

    def __init__(self, n_wind: int, n_air: int, n_balls: int) -> None:
        self.wind_groups, self.air_groups, self.balls = range(n_wind), range(n_air), range(n_balls)


def test_an_unknown_air_sources_mean_density_is_free_a_known_ones_is_held():
    """Two air groups of a range source (index 0) and two of a tour source (index 1), every group 5 % thin: the range
    groups sit on their source's mean and cost only (log 0.95 / 0.1)^2 / 2; the tour groups cost their own distance
    from the stated air, 2 (log 0.95 / 0.05)^2 / 2, and their mean's (log 0.95 / 0.01)^2 / 2."""
    config = JointConfig(unknown_air_sources=("range",))
    latent = LatentConditions(_Data(0, 4, 0))
    with torch.no_grad():
        latent.log_density.fill_(torch.log(torch.tensor(0.95)))
    sources = ["range", "tour"]
    air_source = torch.tensor([0, 0, 1, 1])
    wind_source = torch.zeros(0, dtype=torch.long)
    total = float(latent.prior(config, wind_source, air_source, sources).detach())
    x = float(torch.log(torch.tensor(0.95)))
    tour_groups = 2 * (x / config.density_prior) ** 2
    expected = 0.5 * (tour_groups + (x / config.unknown_mean_density_prior) ** 2 + (x / config.mean_density_prior) ** 2)
    assert total == pytest.approx(expected, rel=1e-5)
    factors = latent.source_density_factors(config, air_source, sources)
    assert factors.tolist() == [pytest.approx([0.95, 1.0])]


def test_heavy_shots_are_spread_over_batches_at_the_same_total_weight():
    """Weights 1, 2.5 and 0.2: the 2.5 shot becomes three copies of 2.5/3; the others stay single."""
    from golfflight.model_export.joint import spread_heavy_rows
    from golfflight.model_export.observations import ObservedShots

    n = 3
    fields = {name: torch.zeros(n, 3) for name in ObservedShots.__dataclass_fields__}
    fields["weight"] = torch.tensor([1.0, 2.5, 0.2])
    fields["source"] = torch.tensor([0, 1, 2])
    spread = spread_heavy_rows(ObservedShots(**fields))
    assert spread.source.tolist() == [0, 1, 1, 1, 2]
    assert spread.weight.tolist() == pytest.approx([1.0, 2.5 / 3, 2.5 / 3, 2.5 / 3, 0.2])
    assert float(spread.weight.sum()) == pytest.approx(3.7)
