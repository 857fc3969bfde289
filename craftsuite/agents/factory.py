"""Agents built and loaded: every method of ``craftsuite.methods.METHODS`` built into the
SB3 agent that holds a trained member (``make_agent(method, env, ...)``: what the population
engine saves), a saved agent loaded by ``load_agent``.

Grid methods are DQN (``AutomatonDQN``), MuJoCo methods TD3 (``AutomatonTD3``); the table
says which sees the automaton state and how it uses the automaton. A teacher is
``product-dqn`` on a 7x7 grid; ``distill_from_replay`` turns an SB3-trained teacher's
checkpoint into a table.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import gymnasium as gym
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import VecEnv

from ..hyperparameters import algorithm_settings
from ..methods import ALGORITHMS, METHODS, Method, check_methods
from ..envs.base import CraftWorld
from ..envs.grid import GridWorldEnv
from ..ids import parse_id, world_kind
from .crm import CRMReplayBuffer
from .distillation import AutomatonQTable, DistilledTarget, dynamic_distillation, static_distillation
from .dqn import AutomatonDQN
from .noise import make_action_noise
from .td3 import AutomatonTD3

CLASSES = {"dqn": AutomatonDQN, "td3": AutomatonTD3}
assert set(CLASSES) == set(ALGORITHMS), "every algorithm of the methods table needs its class here"


def make_agent(method: str, env, *, table: AutomatonQTable | None = None, seed: int = 0,
               n_envs: int = 1, rho: float | None = None, self_loops: bool | None = None, verbose: int = 0,
               env_kwargs: dict | None = None, automaton_state: bool | None = None, **overrides):
    """An untrained SB3 agent of ``method``, built as the population engine saves a member
    (``population.train.save_member``): it acts and saves, and its settings are checked;
    it does not learn (``learn`` names ``craftsuite.population.train_population``).

    ``env`` is a CraftSuite id (the agent gets ``n_envs`` copies of it, made with
    ``env_kwargs``, e.g. ``{"layout_seed": 0}`` for a fixed grid instance) or an env made
    already: a gymnasium env or an SB3 VecEnv of a CraftSuite world (``n_envs`` and
    ``env_kwargs`` are then its own). Either way the method must suit the world (a grid
    method on a grid, a MuJoCo method in MuJoCo) and see the automaton state exactly when it
    is a product method (``product=True``). ``rho`` and ``self_loops`` go to the distilled
    target (``DistilledTarget``; None: the method's); ``overrides`` to the algorithm,
    checked by name and type (``craftsuite.hyperparameters.check_hyperparameters``; TD3's
    ``action_noise`` may be a spec such as ``{"type": "persistent", "sigma": 0.6,
    "resample": 0.1}``: ``agents/noise.py``)."""
    check_methods([method])
    m = METHODS[method]
    product = m.observes(automaton_state)  # a MethodError naming both, for a method that cannot go without
    kwargs = algorithm_settings(m.algorithm, overrides)  # bad settings are named before an env is made
    if isinstance(env, str):
        if world_kind(parse_id(env)[1]) != m.world:
            raise ValueError(f"method {method!r} is for {m.world} worlds, not {env}")
        env = make_vec_env(env, n_envs=n_envs, seed=seed, env_kwargs={**(env_kwargs or {}), "product": product})
    else:
        if env_kwargs:
            raise ValueError("env_kwargs make an env from an id; this env is made already")
        _check_suited(method, m, env, product)  # a gymnasium env stays one: SB3 wraps it (Monitor, DummyVecEnv)
    n_envs = env.num_envs if isinstance(env, VecEnv) else 1
    base = _unwrapped(env)
    automaton = base.automaton
    if isinstance(kwargs.get("action_noise"), dict):
        kwargs["action_noise"] = make_action_noise(kwargs["action_noise"], env.action_space.shape[0], seed, n_envs)
    if m.crm:
        kwargs["replay_buffer_class"] = CRMReplayBuffer
        kwargs["replay_buffer_kwargs"] = {"automaton": automaton, "completion_reward": base.task.completion_reward,
                                          **(kwargs.get("replay_buffer_kwargs") or {})}
    target = m.target_kwargs(rho=rho, self_loops=self_loops)
    if m.distill == "dynamic":
        if table is None:
            raise ValueError(f"method {method!r} needs a teacher's table (distill_from_replay)")
        kwargs["distill"] = DistilledTarget(table, automaton, **target)
    elif m.distill == "static":
        kwargs["distill"] = DistilledTarget(table or static_distillation(
            automaton, completion_reward=base.task.completion_reward), automaton, **target)
    return CLASSES[m.algorithm]("MlpPolicy", env, seed=seed, verbose=verbose, **kwargs)


def _unwrapped(env):
    """The world under a gymnasium env or under a VecEnv's first env."""
    return env.get_attr("unwrapped", [0])[0] if isinstance(env, VecEnv) else env.unwrapped


def _check_suited(name: str, method: Method, env, product: bool) -> None:
    """Raise unless ``env`` (a gymnasium env or a VecEnv) is a CraftSuite world of the
    method's kind, with the automaton state in its observation exactly when ``product``."""
    if not isinstance(env, (VecEnv, gym.Env)):
        raise TypeError(f"make_agent takes a CraftSuite id, a gymnasium env or a VecEnv, not {env!r}")
    base = _unwrapped(env)
    if not isinstance(base, CraftWorld):
        raise ValueError(f"method {name!r} needs a CraftSuite world, not {type(base).__name__}")
    kind = "Grid" if isinstance(base, GridWorldEnv) else "Cont"  # the world kinds: WORLD_KINDS
    spec = env.get_attr("spec", [0])[0] if isinstance(env, VecEnv) else env.spec
    where = spec.id if spec is not None else f"this {type(base).__name__}"
    if kind != method.world:
        raise ValueError(f"method {name!r} is for {method.world} worlds, not {where}")
    seen = env.observation_space.shape[0] == base.observation_space.shape[0] + base.automaton.n_states
    if seen != product:
        raise ValueError(f"method {name!r} {'needs' if product else 'must not see'} the automaton state in "
                         f"its observation: make {where} with product={product}")


def distill_from_replay(teacher: AutomatonDQN, chunk: int = 4096) -> AutomatonQTable:
    """Dynamic distillation of a DQN teacher with its SB3 replay (an SB3-trained teacher
    run's checkpoint): mean Q of the taken action per (w, sigma)."""
    buf = teacher.replay_buffer
    rows = buf.buffer_size if buf.full else buf.pos
    if rows == 0:
        raise ValueError("the teacher's replay buffer is empty: train it first")
    obs = buf.observations[:rows].reshape(rows * buf.n_envs, -1)
    actions = buf.actions[:rows].reshape(-1).astype(np.int64)
    q = np.concatenate([teacher.q_values(obs[i:i + chunk]) for i in range(0, len(obs), chunk)])
    q_taken = q[np.arange(len(actions)), actions]
    automaton = _unwrapped(teacher.get_env()).automaton
    return dynamic_distillation(automaton, buf.w[:rows].reshape(-1), buf.sigma[:rows].reshape(-1), q_taken)


def recorded_algorithm(path) -> str | None:
    """The algorithm (a key of ``CLASSES``) a saved agent records in its model's metadata
    (``algorithm``, which every CraftSuite agent saves); None where it records none (a plain
    SB3 checkpoint) or cannot be read."""
    try:
        with zipfile.ZipFile(path) as z:
            data = json.loads(z.read("data"))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None  # damaged or foreign: loading will say more
    return data["algorithm"] if isinstance(data.get("algorithm"), str) else None


def saved_agent_file(path) -> Path:
    """``path`` as a saved agent's file, before anything is built to load it.

    Raises:
        FileNotFoundError: no file there.
        ValueError: a file that is no stable-baselines3 checkpoint (not a zip archive).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no saved agent at {path}")
    if not zipfile.is_zipfile(path):
        raise ValueError(f"{path} is not a saved agent: not a stable-baselines3 checkpoint "
                         "(not a zip archive: corrupt or another file?)")
    return path


def load_agent(path, env=None):
    """Load a saved agent (any CraftSuite method, or a plain stable-baselines3 checkpoint)
    with a clear error for missing or corrupt files. Its class is the one its algorithm
    names (``recorded_algorithm``). A saved agent holds no replay: an off-policy one is
    loaded with a replay of one row (SB3 would allocate one of the saved size up front: a
    CRM student's, a row per live automaton state, can exceed the machine's memory); load
    a replay after it with ``load_replay_buffer``."""
    import stable_baselines3 as sb3

    path = saved_agent_file(path)
    algorithm = recorded_algorithm(path)
    if algorithm is not None:
        if algorithm not in CLASSES:
            raise ValueError(f"{path} is a {algorithm!r} agent, which this CraftSuite does not know "
                             f"(it knows {', '.join(CLASSES)}): a newer CraftSuite saved it?")
        try:
            return CLASSES[algorithm].load(path, env=env, device="cpu", buffer_size=1)
        except Exception as err:  # damaged inside: whatever SB3 raises
            raise ValueError(f"{path} could not be loaded as {CLASSES[algorithm].__name__}: "
                             f"{type(err).__name__}: {err}") from None
    # The model names no algorithm: a plain SB3 checkpoint, tried class by class.
    errors = []
    for cls in (AutomatonDQN, AutomatonTD3, sb3.DQN, sb3.TD3, sb3.SAC, sb3.PPO, sb3.A2C, sb3.DDPG):
        try:
            return cls.load(path, env=env, device="cpu")
        except Exception as err:  # a checkpoint of another algorithm, or damaged inside
            errors.append(f"{cls.__name__}: {type(err).__name__}")
    raise ValueError(f"{path} could not be loaded: {'; '.join(errors)}")
