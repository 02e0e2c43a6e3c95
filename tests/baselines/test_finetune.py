"""PPO fine-tuning of a distilled policy.

The warm-up fits only the value network, the result plays as a trained row, bad requests are
errors.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3", reason="needs the rl extra")
import torch  # noqa: E402

from baselines.distill import DAgger, DAggerSettings, distill, validation_rank  # noqa: E402
from baselines.evaluation import MANIPULATOR_V1, load_policy, play  # noqa: E402
from baselines.finetune import (  # noqa: E402
    ALGO,
    FinetuneSettings,
    add_finetune_parser,
    finetune,
    value_parameters_only,
)

TINY = FinetuneSettings(timesteps=512, value_warmup=256, num_envs=4, n_steps=64, batch_size=64,
                        n_epochs=2, validation=2, validate_every=256)


@pytest.fixture(scope="module")
def distilled(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A tiny time-aware distilled manipulator policy (HybridPPO) of the LQR, seed 2."""
    settings = DAggerSettings(rounds=0, episodes=1, gradient_steps=50, net_arch=(16,),
                              validation=1, observe_time=True)  # fmt: skip
    folder = tmp_path_factory.mktemp("distilled")
    return distill(MANIPULATOR_V1, "lqr", settings, seed=2, output=folder,
                   eval_episodes=1).with_suffix(".json")


def test_the_warm_up_moves_the_value_network_alone(distilled: Path) -> None:
    model = DAgger.load(distilled.with_suffix(".zip"))
    before = {n: p.detach().clone() for n, p in model.policy.named_parameters()}
    value_parameters_only(model.policy, frozen=True)
    optimizer = torch.optim.SGD(model.policy.parameters(), lr=0.1)
    loss = sum((p ** 2).sum() for p in model.policy.parameters() if p.requires_grad)
    loss.backward()  # type: ignore[union-attr]
    optimizer.step()
    changed = {n for n, p in model.policy.named_parameters() if not torch.equal(p, before[n])}
    assert changed and all("value_net" in n for n in changed)
    value_parameters_only(model.policy, frozen=False)
    assert all(p.requires_grad for p in model.policy.parameters())


def test_a_fine_tuned_policy_is_written_and_plays_as_a_trained_row(distilled: Path,
                                                                   tmp_path: Path) -> None:
    path = finetune(distilled, TINY, tmp_path, eval_episodes=1)
    assert path.name == "BlockableManipulator-v1_time_dagger+ppo_seed2.zip"
    config = json.loads(path.with_suffix(".json").read_text())
    assert config["algo"] == ALGO and config["seed"] == 2
    assert config["num_timesteps"] >= TINY.value_warmup + TINY.timesteps
    entry = config["finetuning"]
    assert entry["distilled"] == distilled.stem and entry["validated_at"] == [0, 256, 512]
    # the kept policy is the best validated one, the later on a tie
    ranks = [validation_rank(success, cost) for success, cost
             in zip(entry["validation_success"], entry["validation_cost"], strict=True)]
    assert entry["kept_at"] == max(at for at, rank in zip(entry["validated_at"], ranks,
                                                          strict=True) if rank == min(ranks))
    assert config["algo_kwargs"]["observe_time"] and config["env_kwargs"]["action_mode"] == "hybrid"
    assert (tmp_path / f"{path.stem}_curve.csv").exists() and path.with_suffix(".png").exists()
    tuned = DAgger.load(path).policy
    if entry["kept_at"] > 0:  # PPO's policy: the log std reset to the settings', moved a little
        assert np.allclose(tuned.log_std.detach().numpy(), TINY.log_std, atol=0.05)
    else:  # the distilled policy's actions, the value network warmed up
        start = DAgger.load(distilled.with_suffix(".zip")).policy.state_dict()
        for name, weights in tuned.state_dict().items():
            if "value_net" not in name and name != "log_std":
                assert torch.equal(weights, start[name]), name
    controller = load_policy(path.with_suffix(".json"))
    assert controller.label == ALGO
    episode = play(MANIPULATOR_V1, controller.make_policy, 0, **controller.env_kwargs)
    assert episode.num_steps > 0 and episode.brake_use is not None


def test_bad_requests_are_errors(distilled: Path, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="learning_rate"):
        FinetuneSettings(learning_rate=0.0)
    with pytest.raises(ValueError, match="gamma"):
        FinetuneSettings(gamma=1.5)
    with pytest.raises(ValueError, match="validation_scales"):
        FinetuneSettings(validation_scales=(0.1, 0.01))
    record = json.loads(distilled.read_text())
    (tmp_path / "ppo.json").write_text(json.dumps({**record, "algo": "PPO"}))
    with pytest.raises(ValueError, match="not a distilled"):
        finetune(tmp_path / "ppo.json", TINY, tmp_path)
    parser = argparse.ArgumentParser()
    add_finetune_parser(parser.add_subparsers())
    args = parser.parse_args(["finetune", MANIPULATOR_V1, "--seeds", "7",
                              "--distilled", str(tmp_path), "--output", str(tmp_path)])
    with pytest.raises(SystemExit, match="no distilled policy"):
        args.handler(args)
