"""RLlib PPO on a mission env under its registered id: the clear error and one iteration."""

from __future__ import annotations

import pytest

from baselines.rllib import check_env_id

MANIPULATOR = "mdi_envs/BlockableManipulator-v0"


def test_unknown_ids_get_a_clear_error_naming_both_forms() -> None:
    check_env_id(MANIPULATOR)
    check_env_id("mdi_envs:mdi_envs/BlockableManipulator-v0")  # gym imports the module
    with pytest.raises(ValueError, match="register_env.*mdi_envs:mdi_envs/"):
        check_env_id("mdi_envs/BlockableManipulator-v9")


@pytest.mark.slow
def test_one_rllib_ppo_iteration_on_the_registered_id() -> None:
    pytest.importorskip("ray.rllib", reason="RLlib is in the rllib extra, not in "
                        "test: it pins gymnasium (pip install 'mdi-envs[rllib]')")  # fmt: skip
    import ray

    from baselines.rllib import ppo_config, train_rllib

    config = ppo_config(MANIPULATOR, num_env_runners=1, num_envs_per_env_runner=2,
                        train_batch_size=256, minibatch_size=128, num_epochs=1)  # fmt: skip
    assert config.env == MANIPULATOR and config.gamma == 0.99
    assert config.env_config == {"shaping_discount": 0.99}  # the shipped PPO entry's
    ray.init(num_cpus=2, include_dashboard=False)
    try:
        (row,) = train_rllib(config, iterations=1)
    finally:
        ray.shutdown()
    assert row["env_steps"] >= 256


def test_a_linear_learning_rate_becomes_rllibs_piecewise_schedule() -> None:
    pytest.importorskip("ray.rllib", reason="RLlib is in the rllib extra")
    from baselines.hyperparameters import get_hyperparameters
    from baselines.rllib import ppo_config

    robot = "mdi_envs/DiffDriveRobot-v1"
    entry = get_hyperparameters(robot, "PPO")
    initial = float(entry["algo_kwargs"]["learning_rate"].removeprefix("lin_"))
    assert ppo_config(robot).lr == [[0, initial], [entry["total_timesteps"], 0.0]]
    assert ppo_config(MANIPULATOR).lr == get_hyperparameters(MANIPULATOR, "PPO")[
        "algo_kwargs"]["learning_rate"]
