"""Runs trained side by side (`model_export.stacked_runs`, `joint.train_joint_runs`): each stacked run computes and
steps as it would alone."""

import copy
import json

import pytest
import torch
from golfflight.model_export.joint import JointConfig, train_joint, train_joint_runs
from golfflight.model_export.real_training import SeedPlan, train_seeds
from golfflight.model_export.stacked_runs import StackedNetworks, clip_per_run, runs_held
from golfflight.model_export.training import load_checkpoint
from golfflight.model_export.variants import PhysNN, PhysQ
from test_real_training import REPO_ROOT, _windy_set

from golfflight.cli import main


def _shots(n: int, seed: int) -> tuple[torch.Tensor, torch.Tensor]:
    g = torch.Generator().manual_seed(seed)
    return torch.rand(n, 3, generator=g) * 60 + 5, torch.rand(n, 3, generator=g) * 400


def test_each_stacked_run_goes_through_its_own_weights():
    torch.manual_seed(0)
    modules = [PhysNN("phys-nn+", (8, 4)) for _ in range(3)]
    stacked = StackedNetworks(modules[0], 3)
    with torch.no_grad():
        for r, module in enumerate(modules):
            for name, value in module.named_parameters():
                stacked.params[name][r] = value
    v_rel, omega = _shots(3 * 5, 1)
    got = stacked(v_rel, omega)
    for r, module in enumerate(modules):
        rows = slice(5 * r, 5 * (r + 1))
        torch.testing.assert_close(got[rows], module(v_rel[rows], omega[rows]), rtol=1e-6, atol=1e-7)
        assert all(torch.equal(stacked.run_state(r)[k], v) for k, v in module.state_dict().items())


def test_one_stacked_run_is_the_module_itself_bit_for_bit():
    torch.manual_seed(1)
    for module in (PhysNN("phys-nn+", (8,)), PhysQ()):
        v_rel, omega = _shots(7, 2)
        assert torch.equal(StackedNetworks(module, 1)(v_rel, omega), module(v_rel, omega))


def test_each_run_is_clipped_as_torch_clips_it_alone():
    g = torch.Generator().manual_seed(3)
    grads = [torch.randn(2, 4, 3, generator=g), torch.randn(2, 5, generator=g)]
    grads[0][1] *= 1e-3  # run 1 under the norm: left as it is
    params = [torch.zeros_like(x, requires_grad=True) for x in grads]
    for p, x in zip(params, grads):
        p.grad = x.clone()
    clip_per_run(params, 1.0, 2)
    for run in range(2):
        alone = [torch.zeros_like(x[run], requires_grad=True) for x in grads]
        for p, x in zip(alone, grads):
            p.grad = x[run].clone()
        torch.nn.utils.clip_grad_norm_(alone, 1.0)
        for p, a in zip(params, alone):
            torch.testing.assert_close(p.grad[run], a.grad)


def test_a_held_run_keeps_its_weights_and_moments_while_the_others_step():
    weight = torch.nn.Parameter(torch.ones(3, 2))
    optimizer = torch.optim.Adam([weight], lr=0.1)
    for held in (torch.tensor([False, True, False]), torch.tensor([True, False, False])):
        weight.grad = torch.ones(3, 2)
        before = weight.detach().clone()
        moments = {k: v.clone() for k, v in optimizer.state.get(weight, {}).items() if k != "step"}
        with runs_held(optimizer, held):
            optimizer.step()
        assert torch.equal(weight[held], before[held])
        assert not torch.equal(weight[~held], before[~held])
        for name in ("exp_avg", "exp_avg_sq"):
            kept = moments[name][held] if moments else torch.zeros(int(held.sum()), 2)
            assert torch.equal(optimizer.state[weight][name][held], kept)


def test_seeds_trained_side_by_side_are_the_seeds_trained_alone(tmp_path):
    _windy_set(tmp_path / "windy.csv", {"a": (0.0, 1.0), "b": (1.0, 0.0)}, n_per_group=8)
    torch.manual_seed(0)
    start = PhysNN("phys-nn+", (8,))
    before = copy.deepcopy(start.state_dict())
    configs = [JointConfig(epochs=2, batch_size=4, lr=3e-3, seed=seed) for seed in (0, 1)]
    stacked = train_joint_runs(tmp_path / "windy.csv", [tmp_path / "side" / f"seed-{c.seed}" for c in configs],
                               configs, start, progress=False)
    alone = [train_joint(tmp_path / "windy.csv", tmp_path / "alone" / f"seed-{c.seed}", c, copy.deepcopy(start),
                         progress=False) for c in configs]
    checkpoints = [[load_checkpoint(r.out_dir / "last.pt") for r in runs] for runs in (stacked, alone)]
    assert any(not torch.equal(a, b) for a, b in zip(checkpoints[0][0]["model"].values(),
                                                     checkpoints[0][1]["model"].values())), "the seeds differ"
    for side, solo in zip(*checkpoints):
        for part in ("model", "latent", "noise"):
            assert side[part].keys() == solo[part].keys()
            for name in side[part]:
                torch.testing.assert_close(side[part][name], solo[part][name], rtol=1e-5, atol=1e-6)
    for side, solo in zip(stacked, alone):
        assert side.final["val_loss"] == pytest.approx(solo.final["val_loss"], rel=1e-5)
        assert [row["train_loss"] for row in side.history] == pytest.approx(
            [row["train_loss"] for row in solo.history], rel=1e-5)
        assert json.loads((side.out_dir / "conditions.json").read_text()).keys() == {
            "wind", "air", "ball", "noise_factors"}
    assert [load_checkpoint(r.out_dir / "last.pt")["config"]["seed"] for r in stacked] == [0, 1]
    assert all(torch.equal(before[name], value) for name, value in start.state_dict().items()), "the start moved"


def test_runs_side_by_side_must_differ_only_in_their_seed(tmp_path):
    configs = [JointConfig(seed=0), JointConfig(seed=1, lr=1e-2)]
    with pytest.raises(ValueError, match="only in their seed; seeds \\[1\\]"):
        train_joint_runs(tmp_path / "none.csv", [tmp_path / "a", tmp_path / "b"], configs, PhysQ(), progress=False)
    with pytest.raises(ValueError, match="one folder a run"):
        train_joint_runs(tmp_path / "none.csv", [tmp_path / "a"], configs[:1] * 2, PhysQ(), progress=False)


def test_train_real_trains_its_seeds_stacked_each_in_its_folder(tmp_path):
    _windy_set(tmp_path / "windy.csv", {"a": (0.0, 1.0)}, n_per_group=6)
    configs = {f"seed-{s}": JointConfig(epochs=1, batch_size=4, seed=s, weights={"sentry-2022": 1.0}) for s in (3, 4)}
    runs = train_seeds(tmp_path / "windy.csv", tmp_path / "work", REPO_ROOT / "models" / "default", configs,
                        SeedPlan(threads=1, stacked=True), False)
    assert list(runs) == ["seed-3", "seed-4"]
    for name, run in runs.items():
        assert run.out_dir == tmp_path / "work" / name and run.final["epoch"] == 1
        assert load_checkpoint(run.out_dir / "last.pt")["config"]["seed"] == configs[name].seed


def test_stacked_seeds_shared_out_over_processes_are_the_seeds_stacked_in_one(tmp_path):
    """`--stack-seeds --jobs 2`: seeds 0 and 2 stacked in one process, 1 in another, each in its folder."""
    _windy_set(tmp_path / "windy.csv", {"a": (0.0, 1.0)}, n_per_group=6)
    configs = {f"seed-{s}": JointConfig(epochs=1, batch_size=4, seed=s, weights={"sentry-2022": 1.0})
               for s in (0, 1, 2)}
    init = REPO_ROOT / "models" / "default"
    shared = train_seeds(tmp_path / "windy.csv", tmp_path / "shared", init, configs,
                          SeedPlan(jobs=2, threads=1, stacked=True), False)
    one = train_seeds(tmp_path / "windy.csv", tmp_path / "one", init, configs, SeedPlan(threads=1, stacked=True),
                       False)
    assert list(shared) == list(configs)
    for name, run in shared.items():
        assert run.out_dir == tmp_path / "shared" / name
        weights = [load_checkpoint(r.out_dir / "last.pt")["model"] for r in (run, one[name])]
        for key in weights[0]:
            torch.testing.assert_close(weights[0][key], weights[1][key], rtol=1e-5, atol=1e-6)


def test_stacked_seeds_on_a_gpu_are_one_process(tmp_path, capsys, monkeypatch):
    from golfflight.model_export import real_training

    monkeypatch.setattr(real_training, "resolve_device", lambda name: torch.device("cuda"))
    assert main(["train-real", "--work", str(tmp_path / "work"), "--data-root", str(tmp_path), "--stack-seeds",
                 "--jobs", "2", "--device", "cuda", "--quiet"]) == 2
    assert "--jobs 2 goes with --device cpu: on cuda the seeds run one after another, or side by side with " \
           "--stack-seeds" in capsys.readouterr().err
    assert not (tmp_path / "work").exists()


@pytest.mark.parametrize("seeds", [(0,), (0, 1)])
def test_a_compiled_step_trains_the_runs_the_eager_step_trains(tmp_path, seeds):
    """`train-real --compile` (and with `--stack-seeds`): the Euler step fused by torch.compile, forward and
    backward, changes rounding only. Each case starts from an empty compile cache: torch.compile keeps its versions
    of the Euler step (`flight.rollout.step_rule`) by the function, and past eight it would run eager unseen."""
    torch._dynamo.reset()
    _windy_set(tmp_path / "windy.csv", {"a": (0.0, 1.0)}, n_per_group=6)
    torch.manual_seed(0)
    start = PhysNN("phys-nn+", (8,))
    configs = [JointConfig(epochs=1, batch_size=4, lr=3e-3, seed=seed) for seed in seeds]
    eager = [train_joint(tmp_path / "windy.csv", tmp_path / f"eager-{c.seed}", c, start, progress=False)
             for c in configs]
    fused = train_joint_runs(tmp_path / "windy.csv", [tmp_path / f"compiled-{c.seed}" for c in configs], configs,
                             start, progress=False, compile_step=True)
    for alone, compiled in zip(eager, fused):
        weights = [load_checkpoint(run.out_dir / "last.pt")["model"] for run in (alone, compiled)]
        for name in weights[0]:
            torch.testing.assert_close(weights[1][name], weights[0][name], rtol=1e-4, atol=1e-6)
        assert compiled.final["val_loss"] == pytest.approx(alone.final["val_loss"], rel=1e-4)
