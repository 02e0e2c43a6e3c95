"""Stable-Baselines3 baselines on the ``mdi_envs`` environments (thin layers over SB3).

``vec_env`` adapts the batched vector envs to SB3's ``VecEnv``; ``hyperparameters`` reads the
one table of settings per (env id, objective, algorithm) from the rl-zoo3 YAML files in
``hyperparams/`` (``zoo`` runs rl-zoo3 on them with HybridPPO added); ``train`` trains and
saves a policy with its exact config and a training-curve plot; ``cli`` is the ``mdi-envs
train`` subcommand.
"""
