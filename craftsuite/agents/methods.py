"""Every method of ``craftsuite.methods.METHODS`` built into an agent: ``make_agent(method, env_id, ...)``.

Grid methods are DQN (``AutomatonDQN``), MuJoCo methods TD3 (``AutomatonTD3``); the table
says which sees the automaton state and how it uses the automaton. A teacher is
``product-dqn`` on a 7x7 grid; ``distill_from_replay`` turns it into a table.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
from stable_baselines3.common.env_util import make_vec_env

from ..methods import (  # noqa: F401  (METHODS and the defaults re-exported)
    ALGORITHMS, DQN_DEFAULTS, METHODS, TD3_DEFAULTS, Method, algorithm_settings, check_methods)
from ..registration import parse_id, world_kind
from .crm import CRMReplayBuffer
from .distillation import AutomatonQTable, DistilledTarget, dynamic_distillation, static_distillation
from .dqn import AutomatonDQN
from .noise import make_action_noise
from .td3 import AutomatonTD3

CLASSES = {"dqn": AutomatonDQN, "td3": AutomatonTD3}
assert set(CLASSES) == set(ALGORITHMS), "every algorithm of the methods table needs its class here"


def make_agent(method: str, env_id: str, *, table: AutomatonQTable | None = None, seed: int = 0,
               n_envs: int = 1, rho: float | None = None, self_loops: bool | None = None, verbose: int = 0,
               env_kwargs: dict | None = None, **overrides):
    """An untrained agent of ``method`` on ``n_envs`` copies of ``env_id``: each step of
    the agent collects ``n_envs`` transitions, then takes ``gradient_steps`` updates.

    ``env_kwargs`` go to ``gymnasium.make`` (e.g. ``{"layout_seed": 0}`` for a fixed grid
    instance); ``rho`` and ``self_loops`` to the distilled target (``DistilledTarget``;
    None: the method's); ``overrides`` to the algorithm (TD3's ``action_noise`` may be a
    spec such as ``{"type": "persistent", "sigma": 0.6, "resample": 0.1}``: ``agents/noise.py``)."""
    check_methods([method])
    m = METHODS[method]
    if world_kind(parse_id(env_id)[1]) != m.world:
        raise ValueError(f"method {method!r} is for {m.world} worlds, not {env_id}")
    env = make_vec_env(env_id, n_envs=n_envs, seed=seed, env_kwargs={**(env_kwargs or {}), "product": m.product})
    base = env.envs[0].unwrapped
    automaton = base.automaton
    kwargs = algorithm_settings(m.algorithm, overrides)
    if isinstance(kwargs.get("action_noise"), dict):
        kwargs["action_noise"] = make_action_noise(kwargs["action_noise"], env.action_space.shape[0], seed, n_envs)
    if m.crm:
        kwargs["replay_buffer_class"] = CRMReplayBuffer
        kwargs["replay_buffer_kwargs"] = {"automaton": automaton, "completion_reward": base.task.completion_reward,
                                          **kwargs.get("replay_buffer_kwargs", {})}
    target = m.target_kwargs(rho=rho, self_loops=self_loops)
    if m.distill == "dynamic":
        if table is None:
            raise ValueError(f"method {method!r} needs a teacher's table (distill_from_replay)")
        kwargs["distill"] = DistilledTarget(table, automaton, **target)
    elif m.distill == "static":
        kwargs["distill"] = DistilledTarget(table or static_distillation(
            automaton, completion_reward=base.task.completion_reward), automaton, **target)
    return CLASSES[m.algorithm]("MlpPolicy", env, seed=seed, verbose=verbose, **kwargs)


def distill_from_replay(teacher: AutomatonDQN, chunk: int = 4096) -> AutomatonQTable:
    """Dynamic distillation of a DQN teacher: mean Q of the taken action per (w, sigma)."""
    buf = teacher.replay_buffer
    rows = buf.buffer_size if buf.full else buf.pos
    if rows == 0:
        raise ValueError("the teacher's replay buffer is empty: train it first")
    obs = buf.observations[:rows].reshape(rows * buf.n_envs, -1)
    actions = buf.actions[:rows].reshape(-1).astype(np.int64)
    q = np.concatenate([teacher.q_values(obs[i:i + chunk]) for i in range(0, len(obs), chunk)])
    q_taken = q[np.arange(len(actions)), actions]
    automaton = teacher.get_env().envs[0].unwrapped.automaton
    return dynamic_distillation(automaton, buf.w[:rows].reshape(-1), buf.sigma[:rows].reshape(-1), q_taken)


def load_agent(path, env=None):
    """Load a saved agent (any CraftSuite method, or a plain stable-baselines3 checkpoint)
    with a clear error for missing or corrupt files."""
    import stable_baselines3 as sb3

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no saved agent at {path}")
    if not zipfile.is_zipfile(path):
        raise ValueError(f"{path} is not a saved agent: not a stable-baselines3 checkpoint "
                         "(not a zip archive: corrupt or another file?)")
    errors = []
    for algorithm in (AutomatonDQN, AutomatonTD3, sb3.DQN, sb3.TD3, sb3.SAC, sb3.PPO, sb3.A2C, sb3.DDPG):
        try:
            return algorithm.load(path, env=env, device="cpu")
        except Exception as err:  # a checkpoint of the other algorithm, or damaged inside
            errors.append(f"{algorithm.__name__}: {type(err).__name__}")
    raise ValueError(f"{path} could not be loaded: {'; '.join(errors)}")
