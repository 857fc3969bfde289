"""Frozen updates: what each learning rule of the population engine computes today, on
fixed inputs, kept as fixtures (``<case>.npz`` beside this file) that
``tests/population/test_frozen_updates.py`` asserts today's code still reproduces.

Each case of ``CASES`` is one learning rule (a ``METHODS`` row and a few settings): a
one-member ``Population`` (``craftsuite.population.engine``) over a fixed automaton
(KeySwordDragon's: three live states, an accepting and a rejecting one), its networks set
from fixed numpy draws (online and target nets different, so that double DQN and the
target's Polyak average show), its replay filled with a fixed, seeded stream of 24 vector
steps of 2 envs (episodes that accept, reject and hit the time limit; a replay of 40
transitions, so it has wrapped), then ``UPDATES`` calls of ``Population.train()`` (one
gradient step each; the sampling stream is the replay's own seed, torch is seeded before
each call for TD3's target noise). An ``interleave`` case observes one more vector step
of the stream before each call, as a run does (its rule is counted in transitions: DQN's
hard target update by ``target_update_unit="transitions"``, TD3's delay schedule by the
step). A fixture records:

* ``automaton_*``, ``input_digest``, ``init_digest``: the inputs (if these differ, the
  automaton, the input generator or numpy's streams changed, not a learning rule);
* ``batch_*``: every sampled minibatch (rewards, after n-step sums, CRM relabelling and
  shaping; terminals; discounts; importance weights; leaves; (w, sigma); a digest of the
  observations, which CRM relabels);
* ``targets``, ``td``: every update's TD targets (after the distilled mix) and TD errors;
* ``losses`` (DQN), ``critic_losses`` and ``actor_losses`` (TD3): the scalars backpropagated;
* ``param/<module>``: every parameter after the updates (the networks are [16, 16]; a
  residual CNN's as ``param_digest/<module>``), and ``buffers/<module>`` a residual CNN's
  batch-norm running statistics;
* ``priorities``, ``max_priority`` (prioritized replay: the sum tree's leaves, p ** alpha,
  after the updates) and ``counts`` (distilled targets: the student's count per (w, sigma)).

Regenerate (all cases, or the ones named)::

    .venv/bin/python -m tests.population.frozen.make [case ...]

Regenerating is right ONLY when a learning rule changes on purpose (say so in the
commit, with the cases it changes); a fixture that today's code no longer reproduces is
otherwise a regression to fix in the code, not here. A refactor of the engine must leave
every fixture as it is.
"""

from __future__ import annotations

import sys
import zlib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch as th

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.distillation import AutomatonQTable
from craftsuite.hyperparameters import algorithm_settings
from craftsuite.methods import METHODS
from craftsuite.population.engine import Population
from craftsuite.population.replay import SparseRows
from craftsuite.task_registry import resolve_task

HERE = Path(__file__).resolve().parent
TASK = "KeySwordDragon"  # live states 0, 1, 3; 4 accepts; 2 is the rejecting sink; 8 labels
N_ENVS, STEPS, BUFFER = 2, 24, 40  # 48 transitions into a replay of 40: it wraps
# BATCH * ACT_DIM is a multiple of 16: torch's normal_ fills blocks of 16 (recomputing the
# last block otherwise), so member 0 of several members draws TD3's target noise as one does
BATCH, UPDATES = 32, 8
FEATURES = {"dqn": 8, "td3": 6}  # world entries before the automaton one-hot
SPARSE_WIDTH = 4  # the grid-like DQN observations have at most 3 world nonzeros and the one-hot
ACT_DIM, N_ACTIONS = 2, 4
NET = {"net_arch": [16, 16]}
COMMON = {"batch_size": BATCH, "learning_starts": 0, "buffer_size": BUFFER, "learning_rate": 1e-3,
          "policy_kwargs": NET}
DQN = {**COMMON, "target_update_unit": "gradient_steps", "target_update_interval": 3}
TD3 = {**COMMON, "policy_delay": 2, "tau": 0.05}


@dataclass(frozen=True)
class Case:
    method: str  # a METHODS row: the rule's wiring (distilled target, CRM, shaping)
    settings: dict = field(default_factory=dict)  # over DQN or TD3 above
    interleave: bool = False  # a vector step observed before each update (else the replay stays as filled)
    planes: tuple | None = None  # the world entries as grid planes (C, H, W), for a residual CNN

    @property
    def algorithm(self) -> str:
        return METHODS[self.method].algorithm

    def effective(self) -> dict:
        base = DQN if self.algorithm == "dqn" else TD3
        return algorithm_settings(self.algorithm, {**base, **self.settings})


CASES = {
    # DQN: dueling, double, Huber, prioritized; per-member gradient clipping that bites
    "dqn": Case("dqn", {"max_grad_norm": 0.15}),
    # the other branches: no dueling head, the max target, squared loss, uniform replay
    "dqn-uniform": Case("dqn", {"dueling": False, "double": False, "loss": "mse", "prioritized": False}),
    "dqn-layer-norm": Case("product-dqn", {"layer_norm": True}),
    "dqn-n3": Case("product-dqn", {"n_steps": 3}),
    # the paper's residual CNN over the 8 world entries as 2 planes of 2 x 2 (batch norms in
    # training mode for the update's own Q-values only, the target copying running statistics)
    "dqn-residual-cnn": Case("product-dqn", {"features_extractor": "residual-cnn"}, planes=(2, 2, 2)),
    # the hard target update counted in transitions (SB3's, the default): every 3 vector steps
    "dqn-transitions": Case("product-dqn", {"target_update_unit": "transitions", "target_update_interval": 6},
                            interleave=True),
    "static": Case("static"),  # beta = rho ** count, the static table (value iteration)
    "dynamic": Case("dynamic"),  # a teacher's table with unseen cells (beta = 0 there)
    "dynamic-n3": Case("dynamic", {"n_steps": 3}),
    "crm": Case("crm"),
    "crm-edges": Case("crm-edges"),  # CRM with a distilled target on edges only, rho = 1
    "crm-n3": Case("crm", {"n_steps": 3}),
    "crm-edges-n3": Case("crm-edges", {"n_steps": 3}),
    "rs": Case("rs"),
    "dynamic-rs-n3": Case("dynamic-rs", {"n_steps": 3}),
    # TD3: clipped double-Q, target smoothing, actor delay 2, Polyak, prioritized
    "td3": Case("td3"),
    "td3-uniform-layer-norm": Case("product-td3", {"prioritized": False, "layer_norm": True}),
    # the actor's delay by step: 4 until step 56 (the first 3 updates), then 2
    "td3-delay-schedule": Case("product-td3", {"policy_delay": None, "delay_schedule": [[56, 4], [None, 2]]},
                               interleave=True),
    "td3-static-n3": Case("td3-static", {"n_steps": 3}),
    "td3-dynamic": Case("td3-dynamic"),
    "td3-crm-edges": Case("td3-crm-edges"),
    "td3-rs-n3": Case("td3-rs", {"n_steps": 3}),
}


# -- inputs --------------------------------------------------------------------------------------
def task():
    """The automaton and completion reward every case learns over."""
    spec = resolve_task(TASK)
    return spec.automaton, float(spec.completion_reward)


def teacher_table(automaton) -> AutomatonQTable:
    """A teacher's table for the dynamic methods: seeded values, a third of the cells unseen."""
    rng = np.random.default_rng(11)
    q = rng.normal(30.0, 20.0, size=automaton.delta.shape)
    counts = rng.integers(0, 3, size=automaton.delta.shape) * rng.integers(1, 50, size=automaton.delta.shape)
    return AutomatonQTable(q, counts.astype(np.int64), automaton.fingerprint, automaton.propositions, "dynamic")


def initial_counts(cells: int) -> np.ndarray:
    """The student's counts before the updates: beta = 0.999 ** count from 1 down to ~0.05."""
    return np.random.default_rng(12).integers(0, 3000, size=cells).astype(np.int64)


def stream(algorithm: str, automaton, completion: float) -> list[dict]:
    """``STEPS + UPDATES`` vector steps of ``N_ENVS`` envs (the replay is filled with the
    first ``STEPS``; an ``interleave`` case observes the others between its updates):
    episodes whose automaton state follows ``delta`` under seeded labels (ending where it
    accepts or rejects, or by the time limit), rewards of -0.1 (and noise, and the
    completion bonus on acceptance), observations of a few world entries then the automaton
    one-hot (sparse, grid-like, for DQN; dense for TD3)."""
    rng = np.random.default_rng(7 if algorithm == "dqn" else 8)
    S, F = automaton.n_states, FEATURES[algorithm]
    labels = automaton.delta.shape[1]

    def observe(w):
        x = np.zeros(F + S, dtype=np.float32)
        if algorithm == "dqn":
            at = rng.choice(F, size=rng.integers(1, 4), replace=False)
            x[at] = rng.choice([0.5, 1.0, 2.0], size=len(at))
        else:
            x[:F] = rng.normal(size=F)
        x[F + w] = 1.0
        return x

    w = np.zeros(N_ENVS, dtype=np.int64)
    obs = np.stack([observe(0) for _ in range(N_ENVS)])
    steps = []
    for _ in range(STEPS + UPDATES):
        # no label, or one that keeps out of the sink (the episode goes on, or accepts), or any
        safe = [rng.choice(np.flatnonzero(~automaton.rejecting[automaton.delta[v]])) for v in w]
        coin = rng.random(N_ENVS)
        sigma = np.where(coin < 0.4, 0, np.where(coin < 0.9, safe, rng.integers(0, labels, size=N_ENVS)))
        w_next = automaton.delta[w, sigma].astype(np.int64)
        terminated = automaton.accepting[w_next] | automaton.rejecting[w_next]
        truncated = ~terminated & (rng.random(N_ENVS) < 0.1)
        rewards = (-0.1 + 0.05 * rng.normal(size=N_ENVS) + completion * automaton.accepting[w_next]).astype(np.float32)
        next_obs = np.stack([observe(int(v)) for v in w_next])
        if algorithm == "dqn":
            actions = rng.integers(0, N_ACTIONS, size=N_ENVS)
        else:
            actions = rng.uniform(-1, 1, size=(N_ENVS, ACT_DIM)).astype(np.float32)
        steps.append(dict(obs=obs, next_obs=next_obs, actions=actions, rewards=rewards, terminated=terminated,
                          truncated=truncated, w=w.copy(), sigma=sigma, w_next=w_next))
        ended = terminated | truncated
        w = np.where(ended, 0, w_next)
        obs = np.stack([observe(0) if ended[e] else next_obs[e] for e in range(N_ENVS)])
    return steps


def input_digest(steps, table, counts) -> np.ndarray:
    parts = [sum(float(s[k].astype(np.float64).sum()) for s in steps)
             for k in ("obs", "next_obs", "actions", "rewards", "terminated", "truncated", "w", "sigma")]
    parts += [float(table.q.sum()), float(table.counts.sum()), float(counts.sum())]
    return np.array(parts)


# -- the population ------------------------------------------------------------------------------
def set_parameters(learner) -> None:
    """Every parameter from its own seeded draws (by module and name), the same for every
    member: weights as ``nn.Linear`` bounds them, biases and LayerNorm affines near 0 and
    1; the target nets unlike the online ones."""
    with th.no_grad():
        for module, net in learner.modules().items():
            for name, p in net.named_parameters():
                rng = np.random.default_rng(zlib.crc32(f"{module}/{name}".encode()))
                shape = p.shape[1:]  # one member's
                if "norm_weights" in name or "bn_weights" in name:
                    value = 1.0 + rng.uniform(-0.2, 0.2, size=shape)
                elif "norm_biases" in name or "biases" in name:
                    value = rng.uniform(-0.2, 0.2, size=shape)
                else:
                    bound = 1.0 / np.sqrt(shape[0])
                    value = rng.uniform(-bound, bound, size=shape)
                p.copy_(th.as_tensor(value, dtype=p.dtype).expand_as(p))


LARGE = 20_000  # a network with more parameters (a CNN's) is kept as digests: the fixtures stay small


def parameters(learner) -> dict[str, np.ndarray]:
    """Member 0's parameters, ``param/<module>``: its tensors flattened one after the other
    in ``named_parameters`` order; a network of more than ``LARGE`` as ``param_digest/<module>``,
    three numbers per tensor (``digest``)."""
    out = {}
    for module, net in learner.modules().items():
        tensors = [p.detach()[0].cpu().numpy().reshape(-1) for p in net.parameters()]
        if sum(t.size for t in tensors) <= LARGE:
            out[f"param/{module}"] = np.concatenate(tensors)
        else:
            out[f"param_digest/{module}"] = np.concatenate([digest(t) for t in tensors])
    return out


def digest(values: np.ndarray) -> np.ndarray:
    """A tensor as its sum, its sum of magnitudes and a sum weighted by fixed draws (a change
    of any entry, or two entries swapped, moves it)."""
    weights = np.random.default_rng(values.size).uniform(0.5, 1.5, size=values.size)
    x = values.astype(np.float64)
    return np.array([x.sum(), np.abs(x).sum(), (weights * x).sum()])


def statistics(learner) -> dict[str, np.ndarray]:
    """Member 0's batch-norm running statistics, ``buffers/<module>``, for the networks that
    have them (a residual CNN's)."""
    return {f"buffers/{module}": np.concatenate([b[0].cpu().numpy().reshape(-1) for b in net.buffers()])
            for module, net in learner.modules().items() if list(net.buffers())}


def build(name: str, sparse: bool = False, members: int = 1):
    """Case ``name``'s population (one member; ``members``: that many, alike in everything
    but their sampling draws) with its replay filled, before any update; and the inputs it
    was made from (the stream, the table, the initial counts). ``sparse``: its replay stores
    observations as their nonzero entries (the grid students' replay; DQN only)."""
    case = CASES[name]
    automaton, completion = task()
    obs_dim = FEATURES[case.algorithm] + automaton.n_states
    space = gym.spaces.Discrete(N_ACTIONS) if case.algorithm == "dqn" else \
        gym.spaces.Box(-1.0, 1.0, (ACT_DIM,), np.float32)
    table = teacher_table(automaton)
    K = members
    pop = Population(case.method, case.effective(), list(range(K)), N_ENVS, obs_dim, space, automaton, completion,
                     total_steps=10_000, table=table if METHODS[case.method].needs_table else None,
                     sparse_width=SPARSE_WIDTH if sparse else None, planes=case.planes)
    set_parameters(pop.learner)
    counts = initial_counts(automaton.delta.size)
    if pop.learner.targets is not None:
        pop.learner.targets.counts[:] = counts
    steps = stream(case.algorithm, automaton, completion)
    for s in steps[:STEPS]:
        observe(pop, s)
    if not case.interleave:
        steps = steps[:STEPS]
    return pop, dict(automaton=automaton, completion=completion, steps=steps, table=table, counts=counts)


def observe(pop, s: dict) -> None:
    """One vector step of the stream, the same for every member of ``pop``."""
    transitions = np.stack([s["w"], s["sigma"], s["w_next"]], axis=-1)

    def each(x):
        return np.broadcast_to(x[None], (pop.K, *x.shape))

    pop.observe(each(s["obs"]), each(s["next_obs"]), each(s["actions"]), each(s["rewards"]),
                each(s["terminated"].astype(np.float32)), each(transitions), each(s["terminated"] | s["truncated"]))


@contextmanager
def losses_backpropagated(into: list):
    """Every scalar ``backward`` is called on while inside, in order."""
    backward = th.Tensor.backward

    def spy(self, *args, **kwargs):
        into.append(float(self.detach()))
        return backward(self, *args, **kwargs)

    th.Tensor.backward = spy
    try:
        yield
    finally:
        th.Tensor.backward = backward


class MemberZero:
    """The sampling stream of a population of several members in which member 0 draws what
    the one-member population draws (the others draw from a second stream): so member 0's
    minibatches are the fixture's, the others' their own."""

    def __init__(self, rng, others):
        self.rng, self.others = rng, others

    def random(self, size):
        return np.concatenate([self.rng.random((1, *size[1:])), self.others.random((size[0] - 1, *size[1:]))])

    def integers(self, low, high, size):
        return np.concatenate([self.rng.integers(low, high, size=(1, *size[1:])),
                               self.others.integers(low, high, size=(size[0] - 1, *size[1:]))])


def observation_digest(observations, obs_dim: int) -> np.ndarray:
    """Each sample's observation as one number: its entries weighted by their position
    (a relabelled one-hot moves it). Sparse rows are summed as their dense vectors."""
    weights = np.arange(1, obs_dim + 1, dtype=np.float64)
    if isinstance(observations, SparseRows):
        return (observations.value * weights[observations.index]).sum(axis=-1)
    return (np.asarray(observations, dtype=np.float64) * weights).sum(axis=-1)


def torch_seed(update: int) -> int:
    return 1000 + update


def run(name: str, sparse: bool = False, members: int = 1) -> dict:
    """Case ``name`` today: ``UPDATES`` updates of its population (``build``); member 0's
    record, which a fixture keeps."""
    pop, inputs = build(name, sparse, members)
    automaton = inputs["automaton"]
    learner, replay = pop.learner, pop.replay
    record = {"automaton_delta": automaton.delta.astype(np.int64), "automaton_accepting": automaton.accepting.copy(),
              "automaton_rejecting": automaton.rejecting.copy(), "completion_reward": inputs["completion"],
              "input_digest": input_digest(inputs["steps"], inputs["table"], inputs["counts"]),
              "init_digest": np.array([p.detach()[0].double().sum().item() for net in learner.modules().values()
                                       for p in net.parameters()])}
    obs_dim = FEATURES[CASES[name].algorithm] + automaton.n_states
    rng = replay.rng
    if members > 1:
        replay.rng = MemberZero(rng, np.random.default_rng(99))
    batches, targets, tds, losses = [], [], [], []
    sample, td_target, update = replay.sample, learner.td_target, learner.update

    def spy_sample(batch_size):
        batches.append(sample(batch_size))
        return batches[-1]

    def spy_target(*args, **kwargs):
        out = td_target(*args, **kwargs)
        targets.append(out[0, :, 0].cpu().numpy().copy())
        return out

    def spy_update(*args, **kwargs):
        tds.append(update(*args, **kwargs))
        return tds[-1]

    replay.sample, learner.td_target, learner.update = spy_sample, spy_target, spy_update
    try:
        for i in range(UPDATES):
            scalars = []
            if CASES[name].interleave:
                observe(pop, inputs["steps"][STEPS + i])
            th.manual_seed(torch_seed(i))
            with losses_backpropagated(scalars):
                pop.train()
            losses.append(scalars)
    finally:
        replay.sample, learner.td_target, learner.update = sample, td_target, update
        replay.rng = rng
    assert len(batches) == UPDATES == learner.n_updates, "one gradient step per train() call"

    def stacked(get, dtype):
        return np.stack([np.asarray(get(b)) for b in batches]).reshape(UPDATES, BATCH).astype(dtype)

    record.update({
        "batch_rewards": stacked(lambda b: b.rewards[0], np.float32),
        "batch_terminals": stacked(lambda b: b.terminals[0], np.float32),
        "batch_weights": stacked(lambda b: b.weights[0], np.float32),
        "batch_leaves": stacked(lambda b: b.leaves[0], np.int32),
        "batch_w": stacked(lambda b: b.w[0], np.int8),
        "batch_sigma": stacked(lambda b: b.sigma[0], np.int8),
        "batch_obs": stacked(lambda b: observation_digest(b.observations, obs_dim)[0], np.float32),
        "batch_next_obs": stacked(lambda b: observation_digest(b.next_observations, obs_dim)[0], np.float32),
        "targets": np.stack(targets).astype(np.float32),
        "td": np.stack([td[0] for td in tds]).astype(np.float32),
    })
    if batches[0].discounts is not None:
        record["batch_discounts"] = stacked(lambda b: b.discounts[0], np.float32)
    if members > 1:
        pass  # what is backpropagated is the members' losses summed
    elif pop.discrete:
        assert all(len(s) == 1 for s in losses)
        record["losses"] = np.array([s[0] for s in losses], dtype=np.float32)
    else:  # the critics' loss at every update, the actor's at every ``policy_delay``-th
        record["critic_losses"] = np.array([s[0] for s in losses], dtype=np.float32)
        record["actor_losses"] = np.array([s[1] for s in losses if len(s) > 1], dtype=np.float32)
    record.update(parameters(learner))
    record.update(statistics(learner))
    if replay.trees is not None:
        record["priorities"] = replay.trees.tree[0, replay.trees.leaves:replay.trees.leaves
                                                 + replay.size * replay.per_step].copy()
        record["max_priority"] = np.float64(replay.max_priority[0])
    if learner.targets is not None:
        record["counts"] = learner.targets.counts[0].copy()
    return record


def path(name: str) -> Path:
    return HERE / f"{name}.npz"


def write(name: str) -> Path:
    record = run(name)
    about = (f"frozen by tests/population/frozen/make.py: case {name!r} = {CASES[name]!r}; "
             f"torch {th.__version__}, numpy {np.__version__}")
    with open(path(name), "wb") as f:
        np.savez_compressed(f, about=np.array(about), **record)
    return path(name)


def main(argv: list[str]) -> int:
    th.set_num_threads(1)  # as the tests run them
    th.use_deterministic_algorithms(True)
    names = argv or list(CASES)
    unknown = [n for n in names if n not in CASES]
    if unknown:
        print(f"unknown case(s) {unknown}; cases: {list(CASES)}", file=sys.stderr)
        return 2
    for name in names:
        out = write(name)
        print(f"{out.relative_to(HERE.parents[2])}: {out.stat().st_size / 1024:.1f} KiB")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
