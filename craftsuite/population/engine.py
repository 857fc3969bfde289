"""One population: K members of one (task, world, method) cell learning side by side.

``Population`` owns the members' learner (``PopulationTD3`` or ``PopulationDQN``), their
replay and exploration, and steps the K x n envs of one vector env: member k acts in its
own n envs, stores in its own replay slice and takes its own gradient steps, in lockstep
with the others. Every learning rule of CraftSuite lives here once: the warm-up of random
actions, exploration noise or epsilon schedule, collection regime (``train_freq``,
``gradient_steps``), target-update interval, TD3 delay schedule, n-step returns
(``n_steps``), CRM and reward shaping (``replay``), and the TD target rules (``dqn``,
``td3``, ``targets``), for SB3's settings of the same names. Where SB3's DQN and TD3 do
otherwise, deliberately: DQN explores with a coin per env (SB3's ``predict`` tosses one for
all envs of a step), and members share one random stream for sampling (their minibatches
are still their own).
"""

from __future__ import annotations

import numpy as np
import torch as th

from ..agents.distillation import AutomatonQTable, DistilledTarget, static_distillation
from ..agents.noise import make_action_noise
from ..methods import METHODS
from ..shaping import Shaping, potential
from .dqn import PopulationDQN
from .envs import step_records
from .nets import hidden_widths
from .replay import CounterfactualView, PopulationReplay
from .targets import MemberTargets
from .td3 import PopulationTD3, delay_at, delay_schedule


class EngineError(ValueError):
    """A run the population engine cannot train (a setting or method it does not support)."""


class Diverged(ValueError):
    """A member whose actor's actions or Q-values are no longer finite: its updates diverged."""


# Settings the engine reads; any other override of a run's algorithm is refused by name
# (it would be silently ignored otherwise).
_READ = {
    "td3": {"learning_rate", "buffer_size", "batch_size", "learning_starts", "gamma", "tau", "target_policy_noise",
            "target_noise_clip", "action_noise", "policy_kwargs", "train_freq", "gradient_steps", "n_steps",
            "prioritized", "replay_buffer_kwargs", "policy_delay", "delay_schedule",
            "stats_window_size", "optimize_memory_usage", "layer_norm"},
    "dqn": {"learning_rate", "buffer_size", "batch_size", "learning_starts", "gamma", "tau", "train_freq",
            "gradient_steps", "target_update_interval", "exploration_fraction", "exploration_initial_eps",
            "exploration_final_eps", "policy_kwargs", "n_steps", "prioritized", "replay_buffer_kwargs",
            "max_grad_norm", "double", "dueling", "loss", "target_update_unit", "features_extractor",
            "stats_window_size", "optimize_memory_usage", "layer_norm"},
}
_POLICY_KWARGS = {"net_arch", "activation_fn", "optimizer_kwargs", "n_critics"}


def check_supported(method: str, settings: dict) -> None:
    """Raise ``EngineError`` naming what the engine, which trains every CraftSuite run, cannot run."""
    algorithm = METHODS[method].algorithm
    why = None
    unknown = sorted(set(settings) - _READ[algorithm])
    if "device" in settings:  # SB3's keyword; the engine's device is its run's, not a setting (nor in the run key)
        why = "device among the settings: the device is the command's --device (train_population's device)"
    elif unknown:
        why = f"the settings {', '.join(map(str, unknown))}"
    elif settings.get("optimize_memory_usage"):
        why = "optimize_memory_usage (its replay keeps next observations; a grid's as their nonzero entries)"
    elif sorted(set(settings.get("policy_kwargs") or {}) - _POLICY_KWARGS):
        why = f"policy_kwargs {', '.join(sorted(set(settings['policy_kwargs']) - _POLICY_KWARGS))}"
    elif (bad_widths := _refused(hidden_widths, settings.get("policy_kwargs") or {}, algorithm, [64])):
        why = bad_widths
    elif not _train_every(settings.get("train_freq", 1)):
        why = f"train_freq {settings['train_freq']!r} (it trains every k steps, not episodes)"
    elif not (isinstance(settings.get("gradient_steps", 1), int) and settings.get("gradient_steps", 1) >= 1):
        why = f"gradient_steps {settings['gradient_steps']!r} (it takes a positive number)"
    elif set(settings.get("replay_buffer_kwargs") or {}) - {"alpha", "beta", "epsilon"}:
        why = f"replay_buffer_kwargs {sorted(set(settings['replay_buffer_kwargs']) - {'alpha', 'beta', 'epsilon'})}"
    elif algorithm == "td3" and not isinstance(settings.get("action_noise"), (dict, type(None))):
        why = "an action_noise object (it takes a spec such as {'type': 'normal', 'sigma': 0.3})"
    if why is not None:
        raise EngineError(f"method {method!r}: the population engine, which trains CraftSuite's runs, does not "
                          f"support {why}; leave it out of the run's settings")
    _check_n_steps(method, settings.get("n_steps", 1))


def _check_n_steps(method: str, n_steps) -> None:
    """Raise ``EngineError`` for a return length no engine runs: not a positive integer."""
    if not isinstance(n_steps, int) or isinstance(n_steps, bool) or n_steps < 1:
        raise EngineError(f"method {method!r}: n_steps must be a positive integer, got {n_steps!r}")


def _refused(check, *args) -> str | None:
    """The message of the ValueError ``check(*args)`` raises, None where it passes."""
    try:
        check(*args)
    except ValueError as err:
        return str(err)
    return None


def _train_every(train_freq) -> int | None:
    if isinstance(train_freq, int) and not isinstance(train_freq, bool) and train_freq >= 1:
        return train_freq
    if isinstance(train_freq, (list, tuple)) and len(train_freq) == 2 and train_freq[1] == "step":
        return _train_every(train_freq[0])
    return None


def member_table(method: str, automaton, completion_reward: float, table: AutomatonQTable | None):
    """The teacher's table a distilled method mixes in (static: solved from the automaton)."""
    row = METHODS[method]
    if row.distill == "static":
        return table or static_distillation(automaton, completion_reward=completion_reward)
    return table


def sparse_width(spec, world_kind: str, product: bool) -> int | None:
    """The most nonzero entries a grid observation of ``spec`` can have (the agent, the
    obstacles, every object, every inventory count, the automaton state), which its replay
    stores instead of the whole vector; None for the continuous worlds, whose observations
    are dense."""
    if world_kind != "Grid":
        return None
    return 1 + len(spec.grid.obstacles) + sum(o.count for o in spec.objects) + len(spec.inventory) + int(product)


def make_replay(method: str, settings: dict, members: int, n_envs: int, obs_dim: int, action_space, automaton,
                completion_reward: float, sparse_width: int | None = None, seed: int = 0,
                shaping: Shaping | None = None) -> PopulationReplay:
    """The replay a population of ``members`` of ``method`` holds (its arrays take memory
    only as transitions are written: made alone, it tells what a population will hold)."""
    row = METHODS[method]
    discrete = row.algorithm == "dqn"
    action_shape, action_dtype = ((), np.int64) if discrete else ((int(action_space.shape[-1]),), np.float32)
    crm = CounterfactualView(automaton, completion_reward, obs_dim) if row.crm else None
    return PopulationReplay(members, int(settings["buffer_size"]), n_envs, obs_dim, action_shape, action_dtype,
                            prioritized=bool(settings.get("prioritized", True)), crm=crm, seed=seed,
                            sparse_width=sparse_width if discrete else None, n_steps=settings.get("n_steps", 1),
                            gamma=float(settings["gamma"]), shaping=shaping,
                            **(settings.get("replay_buffer_kwargs") or {}))


class Population:
    """K members' learner, replay and exploration over one vector env of K x ``n_envs``.

    ``seeds`` are the members' run seeds: member k's envs reset from seed_k + j (as SB3's
    ``make_vec_env`` seeds them), its noise from seed_k (as ``make_agent``). ``sparse_width``:
    a DQN replay's observations stored as their nonzero entries (``sparse_width``).
    ``planes``: the grid's ``(C, H, W)`` (its ``observation_layout``), which a residual CNN
    (``features_extractor="residual-cnn"``) reads."""

    def __init__(self, method: str, settings: dict, seeds: list[int], n_envs: int, obs_dim: int,
                 action_space, automaton, completion_reward: float, total_steps: int,
                 table: AutomatonQTable | None = None, device: str = "cpu", sparse_width: int | None = None,
                 planes: tuple[int, int, int] | None = None):
        check_supported(method, settings)
        row = METHODS[method]
        self.method, self.row, self.settings = method, row, settings
        self.K, self.n_envs, self.seeds = len(seeds), n_envs, list(seeds)
        self.total_steps = total_steps
        self.rng = np.random.default_rng(seeds[0])
        th.manual_seed(seeds[0])
        np.random.seed(seeds[0])  # SB3's normal and OU noises draw from numpy's global stream (as set_random_seed)
        targets = None
        if row.distill is not None:
            rule = DistilledTarget(member_table(method, automaton, completion_reward, table), automaton,
                                   **row.target_kwargs())
            targets = MemberTargets(rule, self.K)
        self.discrete = row.algorithm == "dqn"
        if self.discrete:
            self.n_actions = int(action_space.n)
            self.learner = PopulationDQN(self.K, obs_dim, self.n_actions, settings, targets, device, planes)
            self.noises = []  # epsilon-greedy explores instead
        else:
            self.act_dim = int(action_space.shape[-1])
            self.learner = PopulationTD3(self.K, obs_dim, self.act_dim, settings, targets, device)
            self.delay_schedule = delay_schedule(settings.get("delay_schedule"), settings.get("policy_delay"))
            spec = settings.get("action_noise")
            self.noises = [make_action_noise(spec, self.act_dim, seed, n_envs) if spec else None for seed in seeds]
        shaping = None
        if row.shaping is not None:
            if row.shaping == "dynamic" and table is None:
                raise EngineError(f"method {method!r} shapes with a teacher's values: give its table (table.npz)")
            values = table if row.shaping == "dynamic" else static_distillation(automaton,
                                                                               completion_reward=completion_reward)
            shaping = Shaping(automaton, row.potential_sign * potential(values, automaton), float(settings["gamma"]))
        self.replay = make_replay(method, settings, self.K, n_envs, obs_dim, action_space, automaton,
                                  completion_reward, sparse_width, seed=seeds[0] + 1, shaping=shaping)
        self.batch_size = int(settings["batch_size"])
        self.learning_starts = int(settings["learning_starts"])
        self.gradient_steps = int(settings.get("gradient_steps", 1))
        self.train_every = _train_every(settings.get("train_freq", 1))
        self.num_timesteps = 0  # each member's transitions so far (they move in lockstep)
        self.n_calls = 0  # vector steps, as SB3's _n_calls

    # -- acting ------------------------------------------------------------------------------------
    def exploration_rate(self) -> float:
        """DQN's epsilon at this step: SB3's linear schedule over the run's budget."""
        s = self.settings
        progress = self.num_timesteps / max(self.total_steps, 1)
        start, end, fraction = s["exploration_initial_eps"], s["exploration_final_eps"], s["exploration_fraction"]
        return end if progress > fraction else start + progress * (end - start) / fraction

    def actions(self, obs: np.ndarray) -> np.ndarray:
        """Exploring actions for observations ``(K, n, obs_dim)``."""
        K, n = self.K, self.n_envs
        warm = self.num_timesteps < self.learning_starts
        if self.discrete:
            random = self.rng.integers(0, self.n_actions, size=(K, n))
            if warm:
                return random
            greedy = self.greedy(obs)
            return np.where(self.rng.random((K, n)) < self.exploration_rate(), random, greedy)
        actions = self.rng.uniform(-1, 1, size=(K, n, self.act_dim)).astype(np.float32) if warm \
            else self.greedy(obs)
        for k, noise in enumerate(self.noises):
            if noise is not None:
                actions[k] = np.clip(actions[k] + np.asarray(noise()).reshape(n, self.act_dim), -1, 1)
        return actions

    def restart_noise(self) -> None:
        """Every env's exploration noise anew, as SB3 does at the start of each ``learn``."""
        for noise in self.noises:
            if noise is not None:
                noise.reset()

    def episodes_ended(self, ended: np.ndarray) -> None:
        """Restart the exploration noise of the envs whose episode ended (``(K, n)`` mask)."""
        if not self.noises:
            return
        for k, j in zip(*np.nonzero(ended)):
            noise = self.noises[k]
            if noise is not None:
                noise.reset(indices=[int(j)]) if self.n_envs > 1 else noise.reset()

    def step(self, envs, obs: np.ndarray):
        """One step of every member's envs: act on ``obs`` ``(K * n_envs, obs_dim)``, step
        ``envs`` (same-step autoreset, ``envs.make_envs``), store the transitions, restart
        the noise of envs whose episode ended. Returns (next observations, rewards, ended,
        success, automaton transitions) of the ``K * n_envs`` envs: the transitions ``(w,
        sigma, w')`` each env's action caused, as ``(K * n_envs, 3)`` (``step_records``)."""
        K, n = self.K, self.n_envs
        shaped = obs.reshape(K, n, -1)
        actions = self.actions(shaped)
        next_obs, rewards, terminated, truncated, info = envs.step(actions.reshape(K * n, *actions.shape[2:]))
        ended = terminated | truncated
        real_next, transitions, success = step_records(info, ended, next_obs)
        self.observe(shaped, real_next.reshape(K, n, -1), actions, rewards.reshape(K, n),
                     terminated.reshape(K, n).astype(np.float32), transitions.reshape(K, n, 3), ended.reshape(K, n))
        if ended.any():
            self.episodes_ended(ended.reshape(K, n))
        return next_obs, rewards, ended, success, transitions

    # -- learning ----------------------------------------------------------------------------------
    def observe(self, obs, next_obs, actions, rewards, terminated, transitions, ended=None) -> None:
        """One vector step's transitions, ``(K, n, ...)`` each (``ended``: terminated or
        truncated, which n-step returns stop at); then whatever learning the regime does at
        this step (a target update, ``gradient_steps`` updates)."""
        self.replay.add(obs, next_obs, actions, rewards, terminated, transitions[..., 0], transitions[..., 1],
                        ended)
        self.num_timesteps += self.n_envs
        self.n_calls += 1
        if self.discrete and self.learner.target_update_unit == "transitions":
            if self.n_calls % max(self.learner.target_update_interval // self.n_envs, 1) == 0:
                self.learner.update_target()

    def train(self) -> None:
        if not (self.num_timesteps > 0 and self.num_timesteps > self.learning_starts):
            return
        if self.n_calls % self.train_every:
            return
        delay = None if self.discrete else delay_at(self.delay_schedule, self.num_timesteps)
        for _ in range(self.gradient_steps):
            batch = self.replay.sample(self.batch_size)
            td = self.learner.update(batch) if self.discrete else self.learner.update(batch, delay)
            self.replay.update_priorities(batch.leaves, td)

    def greedy(self, obs: np.ndarray) -> np.ndarray:
        """Greedy actions for observations ``(K, n, obs_dim)``, in training and evaluation alike."""
        actions, outputs = self.learner.act(obs)
        if not np.isfinite(outputs).all():  # (one reduction a step in the common case)
            # named here: the world would refuse NaN thrust, and a DQN would act on an argmax of NaN,
            # naming neither seed nor cause
            k = int(np.flatnonzero(~np.isfinite(outputs.reshape(self.K, -1)).all(axis=1))[0])
            raise Diverged(f"{self.method} seed {self.seeds[k]}: its {self.learner.OUTPUTS} are not finite after "
                           f"{self.num_timesteps:,} transitions, so its learning diverged; run it with a smaller "
                           "learning_rate (or other settings that shrink its updates)")
        return actions

    # -- checkpoints -------------------------------------------------------------------------------
    def member_state(self, k: int) -> dict:
        """Everything member ``k`` resumes from: its networks and optimizer moments, its
        replay slice, distillation counts and noise, and the counters."""
        def sliced(state_dict):
            return {name: t[k].clone() for name, t in state_dict.items()}

        optimizers = {}
        for name, opt in self.learner.optimizers().items():
            state = opt.state_dict()
            optimizers[name] = {
                "state": {i: {key: (v[k].clone() if v.dim() > 0 else v.clone()) for key, v in s.items()}
                          for i, s in state["state"].items()},
                "param_groups": state["param_groups"]}
        targets = self.learner.targets
        return {"modules": {name: sliced(m.state_dict()) for name, m in self.learner.modules().items()},
                "optimizers": optimizers, "replay": self.replay.member_state(k),
                "counts": None if targets is None else targets.counts[k].copy(),
                "noise": None if self.discrete else self.noises[k],
                "num_timesteps": self.num_timesteps, "n_calls": self.n_calls, "n_updates": self.learner.n_updates}

    def load_states(self, states: list[dict]) -> None:
        """Resume every member from its ``member_state``; all at one step. Nothing of
        ``states`` is kept: they may be mapped from their files (``train.read_member_state``)."""
        with th.no_grad():
            for name, module in self.learner.modules().items():
                module.load_state_dict({key: th.stack([s["modules"][name][key] for s in states])
                                        for key in module.state_dict()})
        for name, opt in self.learner.optimizers().items():
            saved = [s["optimizers"][name] for s in states]
            # a 0-d value (Adam's step) copied: the optimizer keeps it for the run, and a tensor
            # of a mapped checkpoint would keep the whole file mapped
            state = {i: {key: (th.stack([s["state"][i][key] for s in saved]) if v.dim() > 0 else v.clone())
                         for key, v in saved[0]["state"][i].items()} for i in saved[0]["state"]}
            opt.load_state_dict({"state": state, "param_groups": saved[0]["param_groups"]})
        for k, s in enumerate(states):
            self.replay.load_member(k, s["replay"])
            if s["counts"] is not None:
                self.learner.targets.counts[k] = s["counts"]
            if not self.discrete:
                self.noises[k] = s["noise"]
        self.num_timesteps, self.n_calls = states[0]["num_timesteps"], states[0]["n_calls"]
        self.learner.n_updates = states[0]["n_updates"]
