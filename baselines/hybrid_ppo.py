"""PPO for a hybrid action space ``Tuple(Discrete(k), Box((m,)))`` (SB3 has no Tuple support).

One categorical choice and m continuous values under one joint distribution.

The manipulator's ``action_mode="hybrid"`` space is ``Tuple(Discrete(2), Box(-1, 1, (1,)))``:
brake released/engaged and the normalised motor torque. The policy is

    pi(c, t | s) = Categorical(c; softmax(logits(s))) * Normal(t; mean(s), diag(exp(log_std))^2)

with ``logits`` (k,) and ``mean`` (m,) from one linear head on the actor's latent and a
state-independent ``log_std`` (m,), as SB3's ``DiagGaussianDistribution``. Log-probability and
entropy are the sums of the two factors'.

Design: inside the algorithm every action is one flat float vector ``[c, t_1, ..., t_m]`` (the
choice index stored as a float), the action space SB3 sees is the Box ``flat_hybrid_space``
(low ``[0, t_low]``, high ``[k - 1, t_high]``), so PPO's rollout buffer, clipping (torques to
their bounds, as for any Box; the index is in range anyway) and update run unchanged. The
conversion to the Tuple happens only at the env boundary: ``HybridPPO`` wraps every env it is
given (constructor, ``set_env``, ``load``) in ``HybridActionVecEnv``, and ``HybridPPO.predict``
returns the env's native format.

Example::

    import gymnasium as gym, mdi_envs
    from stable_baselines3.common.evaluation import evaluate_policy
    from baselines.hybrid_ppo import HybridPPO

    env = gym.make("mdi_envs/BlockableManipulator-v0", action_mode="hybrid")
    model = HybridPPO("MlpPolicy", env, n_steps=256).learn(10_000)
    (brake, torque), _ = model.predict(env.reset()[0], deterministic=True)  # int, (1,) float32
    evaluate_policy(model, env, n_eval_episodes=2)
"""

from __future__ import annotations

from functools import partial
from typing import Any, ClassVar, TypeVar

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3 import PPO
from stable_baselines3.common.distributions import Distribution
from stable_baselines3.common.policies import ActorCriticPolicy, BasePolicy
from stable_baselines3.common.type_aliases import GymEnv, Schedule
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper, is_vecenv_wrapped
from stable_baselines3.common.vec_env.base_vec_env import VecEnvObs, VecEnvStepReturn
from torch import nn
from torch.distributions import Categorical, Normal

SelfHybridDistribution = TypeVar("SelfHybridDistribution", bound="HybridDistribution")
HybridAction = tuple[int, np.ndarray]
"""One native hybrid action: (choice index in {0..k-1}, values (m,) float32)."""


# -- spaces and conversions -----------------------------------------------------------------
def flat_hybrid_space(space: spaces.Space[Any]) -> spaces.Box:
    """The flat Box of a hybrid ``Tuple(Discrete(k), Box(low, high, (m,)))``.

    Returns:
        Box (1 + m,) float32 with low ``[0, low]`` and high ``[k - 1, high]``.

    Raises:
        ValueError: ``space`` is not a Tuple of a Discrete (start 0, k >= 2) and a finite 1-D Box.
    """
    parts = space.spaces if isinstance(space, spaces.Tuple) else ()
    choice, values = parts if len(parts) == 2 else (None, None)
    if not (isinstance(choice, spaces.Discrete) and isinstance(values, spaces.Box)
            and len(values.shape) == 1):
        raise ValueError(f"a hybrid action space is Tuple(Discrete(k), Box((m,))), got {space}")
    if int(choice.start) != 0 or int(choice.n) < 2:
        raise ValueError(f"the Discrete part needs start 0 and n >= 2, got {choice}")
    if not (np.isfinite(values.low).all() and np.isfinite(values.high).all()):
        raise ValueError(f"the Box part needs finite bounds, got {values}")
    low = np.concatenate([[0.0], values.low]).astype(np.float32)
    high = np.concatenate([[int(choice.n) - 1], values.high]).astype(np.float32)
    return spaces.Box(low, high, dtype=np.float32)


def hybrid_space(flat: spaces.Box) -> spaces.Tuple:
    """The inverse of ``flat_hybrid_space``: ``Tuple(Discrete(k), Box((m,)))`` (float32)."""
    return spaces.Tuple((spaces.Discrete(int(flat.high[0]) + 1),
                         spaces.Box(flat.low[1:], flat.high[1:], dtype=np.float32)))  # fmt: skip


def to_hybrid_actions(flat: np.ndarray, num_choices: int) -> HybridAction | list[HybridAction]:
    """Flat actions -> native ones (no clipping of the values).

    Args:
        flat: (1 + m,) one action or (N, 1 + m) a batch; column 0 the choice index (rounded and
            clipped to {0..num_choices-1}), the rest the values.
        num_choices: k.

    Returns:
        (choice int, values (m,) float32) for one action; for a batch a list of N such tuples
        (SB3's per-env layout: ``DummyVecEnv`` hands ``actions[i]`` to env i).
    """
    flat = np.asarray(flat)
    batch = np.atleast_2d(flat)
    choices = np.clip(np.rint(batch[:, 0]), 0, num_choices - 1).astype(np.int64).tolist()
    values = batch[:, 1:].astype(np.float32)
    actions = [(c, v) for c, v in zip(choices, values, strict=True)]
    return actions[0] if flat.ndim == 1 else actions


class HybridActionVecEnv(VecEnvWrapper):
    """A VecEnv with a hybrid action space seen through its flat Box (``flat_hybrid_space``).

    ``step_async`` takes (N, 1 + m) flat actions and passes the wrapped env a list of N native
    tuples (``to_hybrid_actions``), which ``DummyVecEnv`` and ``MoreauJeanVecEnv`` accept.

    Attributes:
        hybrid_action_space: the wrapped env's Tuple space.
    """

    def __init__(self, venv: VecEnv) -> None:
        self.hybrid_action_space = venv.action_space
        super().__init__(venv, action_space=flat_hybrid_space(venv.action_space))
        self.num_choices = int(self.action_space.high[0]) + 1  # type: ignore[attr-defined]

    def step_async(self, actions: np.ndarray) -> None:
        """Convert the (N, 1 + m) flat actions and start the wrapped env's step."""
        self.venv.step_async(to_hybrid_actions(actions, self.num_choices))  # type: ignore[arg-type]

    def reset(self) -> VecEnvObs:
        """Reset the wrapped env."""
        return self.venv.reset()

    def step_wait(self) -> VecEnvStepReturn:
        """The wrapped env's step result, unchanged."""
        return self.venv.step_wait()


# -- distribution and policy ----------------------------------------------------------------
class HybridDistribution(Distribution):
    """Independent Categorical(k) choice x diagonal Gaussian over m values.

    Parameters (``proba_distribution``): ``action_params`` (B, k + m), the k logits then the m
    means, and ``log_std`` (m,). Actions are flat float tensors (B, 1 + m): column 0 the choice
    index, columns 1.. the values. ``log_prob`` and ``entropy`` are (B,) sums of both factors';
    ``mode`` is (argmax of the logits, the means).

    Args:
        num_choices: k, the number of discrete choices.
        action_dim: m, the number of continuous values.
    """

    def __init__(self, num_choices: int, action_dim: int) -> None:
        super().__init__()
        self.num_choices = int(num_choices)
        self.action_dim = int(action_dim)
        self.categorical: Categorical
        self.gaussian: Normal

    def proba_distribution_net(self, latent_dim: int, log_std_init: float = 0.0
                               ) -> tuple[nn.Module, nn.Parameter]:  # fmt: skip
        """The head ``Linear(latent_dim, k + m)`` and the state-independent ``log_std`` (m,)."""
        head = nn.Linear(latent_dim, self.num_choices + self.action_dim)
        log_std = nn.Parameter(th.ones(self.action_dim) * log_std_init, requires_grad=True)
        return head, log_std

    def proba_distribution(self: SelfHybridDistribution, action_params: th.Tensor,
                           log_std: th.Tensor) -> SelfHybridDistribution:  # fmt: skip
        """Set the distribution from ``action_params`` (B, k + m) and ``log_std`` (m,)."""
        logits, means = action_params.split([self.num_choices, self.action_dim], dim=-1)
        self.categorical = Categorical(logits=logits)
        self.gaussian = Normal(means, th.ones_like(means) * log_std.exp())
        self.distribution = [self.categorical, self.gaussian]
        return self

    def log_prob(self, actions: th.Tensor) -> th.Tensor:
        """Log-likelihood (B,) of flat actions (B, 1 + m)."""
        choice = th.round(actions[..., 0]).long()
        return self.categorical.log_prob(choice) + self.gaussian.log_prob(actions[..., 1:]).sum(-1)

    def entropy(self) -> th.Tensor:
        """Entropy (B,): the categorical's plus the Gaussian's (summed over the m values)."""
        return self.categorical.entropy() + self.gaussian.entropy().sum(-1)

    def _join(self, choice: th.Tensor, values: th.Tensor) -> th.Tensor:
        return th.cat([choice.unsqueeze(-1).to(values.dtype), values], dim=-1)

    def sample(self) -> th.Tensor:
        """A flat action (B, 1 + m) (the Gaussian part reparametrised, as SB3)."""
        return self._join(self.categorical.sample(), self.gaussian.rsample())

    def mode(self) -> th.Tensor:
        """The most likely flat action (B, 1 + m): argmax of the logits, the means."""
        return self._join(th.argmax(self.categorical.probs, dim=-1), self.gaussian.mean)

    def actions_from_params(self, action_params: th.Tensor, log_std: th.Tensor,
                            deterministic: bool = False) -> th.Tensor:  # fmt: skip
        """Set the parameters and return actions (B, 1 + m)."""
        self.proba_distribution(action_params, log_std)
        return self.get_actions(deterministic=deterministic)

    def log_prob_from_params(self, action_params: th.Tensor, log_std: th.Tensor
                             ) -> tuple[th.Tensor, th.Tensor]:  # fmt: skip
        """Sampled actions (B, 1 + m) and their log-likelihoods (B,)."""
        actions = self.actions_from_params(action_params, log_std)
        return actions, self.log_prob(actions)


class HybridActorCriticPolicy(ActorCriticPolicy):
    """``ActorCriticPolicy`` with a ``HybridDistribution``.

    The action net maps the actor's latent to k choice logits and m value means; ``log_std``
    (m,) is a state-independent parameter, as in SB3's Gaussian policies.

    Args:
        observation_space: as ``ActorCriticPolicy``.
        action_space: the hybrid Tuple or its ``flat_hybrid_space`` (stored as the flat Box:
            ``predict`` of the policy returns flat (1 + m,) actions, clipped to its bounds).
        lr_schedule: as ``ActorCriticPolicy``.
        **kwargs: ``ActorCriticPolicy``'s (``net_arch``, ``log_std_init``, ...; no gSDE).
    """

    action_dist: HybridDistribution  # type: ignore[assignment]

    def __init__(self, observation_space: spaces.Space[Any], action_space: spaces.Space[Any],
                 lr_schedule: Schedule, **kwargs: Any) -> None:  # fmt: skip
        if isinstance(action_space, spaces.Tuple):
            action_space = flat_hybrid_space(action_space)
        if not (isinstance(action_space, spaces.Box)
                and flat_hybrid_space(hybrid_space(action_space)) == action_space):
            raise ValueError(f"not a hybrid action space or its flat Box: {action_space}")
        if kwargs.get("use_sde"):
            raise ValueError("HybridActorCriticPolicy does not support gSDE (use_sde=True)")
        super().__init__(observation_space, action_space, lr_schedule, **kwargs)

    def _build(self, lr_schedule: Schedule) -> None:
        """Networks and optimizer as ``ActorCriticPolicy._build`` with the hybrid head."""
        space = self.action_space
        self.action_dist = HybridDistribution(int(space.high[0]) + 1,  # type: ignore[attr-defined]
                                              space.shape[0] - 1)  # type: ignore[index]
        self._build_mlp_extractor()
        self.action_net, self.log_std = self.action_dist.proba_distribution_net(
            self.mlp_extractor.latent_dim_pi, log_std_init=self.log_std_init)
        self.value_net = nn.Linear(self.mlp_extractor.latent_dim_vf, 1)
        if self.ortho_init:  # SB3's gains: sqrt(2) hidden, 0.01 action head, 1 value head
            gains: dict[nn.Module, float] = {self.mlp_extractor: np.sqrt(2), self.action_net: 0.01,
                                             self.value_net: 1.0}  # fmt: skip
            extractors = ([self.features_extractor] if self.share_features_extractor
                          else [self.pi_features_extractor, self.vf_features_extractor])
            gains.update({extractor: np.sqrt(2) for extractor in extractors})
            for module, gain in gains.items():
                module.apply(partial(self.init_weights, gain=gain))
        self.optimizer = self.optimizer_class(self.parameters(), lr=lr_schedule(1),
                                              **self.optimizer_kwargs)  # type: ignore[call-arg]

    def _get_action_dist_from_latent(self, latent_pi: th.Tensor) -> Distribution:
        """The hybrid distribution of the actor latent (B, latent_dim)."""
        return self.action_dist.proba_distribution(self.action_net(latent_pi), self.log_std)


# -- algorithm ------------------------------------------------------------------------------
class HybridPPO(PPO):
    """PPO (SB3's, unchanged update) on a ``Tuple(Discrete(k), Box((m,)))`` action space.

    Same constructor, ``learn``, ``save``/``load`` as ``PPO``; ``policy="MlpPolicy"`` is
    ``HybridActorCriticPolicy``. The env (gym env, VecEnv or id) must have the hybrid Tuple
    action space; it is wrapped in ``HybridActionVecEnv``, so ``model.action_space`` is the flat
    Box (the buffer stores (1 + m,) flat actions), ``model.hybrid_action_space`` the Tuple.
    ``predict`` returns native actions (see ``predict``); ``model.policy.predict`` flat ones.
    """

    policy_aliases: ClassVar[dict[str, type[BasePolicy]]] = {  # type: ignore[misc]
        "MlpPolicy": HybridActorCriticPolicy,
    }

    @staticmethod
    def _wrap_env(env: GymEnv, verbose: int = 0, monitor_wrapper: bool = True) -> VecEnv:
        """SB3's wrapping (Monitor, DummyVecEnv), then ``HybridActionVecEnv`` (once).

        Raises:
            ValueError: the env's action space is not hybrid.
        """
        venv = PPO._wrap_env(env, verbose, monitor_wrapper)
        if is_vecenv_wrapped(venv, HybridActionVecEnv):
            return venv
        if not isinstance(venv.action_space, spaces.Tuple):
            raise ValueError("HybridPPO needs a Tuple(Discrete(k), Box((m,))) action space, "
                             f"got {venv.action_space}; use PPO for Box spaces")  # fmt: skip
        return HybridActionVecEnv(venv)

    @property
    def hybrid_action_space(self) -> spaces.Tuple:
        """The env's native ``Tuple(Discrete(k), Box((m,)))``."""
        return hybrid_space(self.action_space)  # type: ignore[arg-type]

    def predict(  # type: ignore[override]
        self,
        observation: np.ndarray | dict[str, np.ndarray],
        state: tuple[np.ndarray, ...] | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = False,
    ) -> tuple[HybridAction | list[HybridAction], tuple[np.ndarray, ...] | None]:
        """Native actions for an observation (obs_dim,) or a batch (N, obs_dim).

        Returns:
            For one observation the tuple (choice int, values (m,) float32) that the gym env's
            ``step`` takes; for a batch a list of N such tuples (what ``DummyVecEnv``,
            ``MoreauJeanVecEnv`` and ``evaluate_policy`` take). Values clipped to their bounds.
            Second element: ``state`` (no recurrence).
        """
        flat, state = self.policy.predict(observation, state, episode_start, deterministic)
        return to_hybrid_actions(flat, int(self.action_space.high[0]) + 1), state  # type: ignore[attr-defined]


__all__ = [
    "HybridActionVecEnv", "HybridActorCriticPolicy", "HybridDistribution", "HybridPPO",
    "flat_hybrid_space", "hybrid_space", "to_hybrid_actions",
]
