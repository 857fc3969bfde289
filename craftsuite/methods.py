"""The methods a benchmark compares, as data: one row per method, named for what it does.

``METHODS`` drives the suites (which methods run in which world), the command line's
choices and the leaderboard's legend; ``craftsuite.agents.methods.make_agent`` builds a row
into an agent. This module imports no torch, so listing methods stays cheap.

A row names its world kind (``Grid``: DQN on the grids, ``Cont``: TD3 in the MuJoCo
world), whether the policy sees the automaton state, and how the student uses the
automaton: a distilled target (``static`` or ``dynamic``, with the ``DistilledTarget``
keywords in ``target``) or counterfactual experience (``crm``). A variant of a method is
a row of its own, never a hyperparameter of a suite, so a leaderboard row says what ran.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from .ids import WORLD_KINDS

# the algorithm family of each world kind: DQN needs discrete moves, TD3 continuous thrust
ALGORITHMS = MappingProxyType({"dqn": "Grid", "td3": "Cont"})
DISTILLATIONS = (None, "static", "dynamic")
TARGET_DEFAULTS = MappingProxyType({"rho": 0.999, "self_loops": True})  # the paper's


# The algorithms' settings before a run's overrides. The authors' DQN, changed where a
# small MLP on one env needs it (measured when the teachers were tuned): a hard target
# update every 100 steps instead of 1,000, and epsilon annealed from 1.0 to 0.1 over the
# first 10% instead of a constant 0.1; with the authors' two, the teacher did not learn
# Blind Craftsman's fixed 7x7 instance in 100k steps, with these it did in 40k. A run
# records these merged with its overrides (``algorithm_settings``) and hashes them into its
# run key, so a change here makes new runs rather than reusing old ones.
DQN_DEFAULTS = dict(learning_rate=5e-4, buffer_size=150_000, batch_size=64, learning_starts=1_000,
                    gamma=0.99, train_freq=1, target_update_interval=100, exploration_fraction=0.1,
                    exploration_initial_eps=1.0, exploration_final_eps=0.1,
                    policy_kwargs=dict(net_arch=[64, 64]))
TD3_DEFAULTS = dict(learning_rate=1e-4, buffer_size=1_000_000, batch_size=64, learning_starts=1_000,
                    gamma=0.99, tau=0.005, target_policy_noise=0.2, target_noise_clip=0.5,
                    action_noise={"type": "normal", "sigma": 0.3},  # a spec (agents/noise.py)
                    policy_kwargs=dict(net_arch=[400, 300]))




class OneOf(tuple):
    """Examples of the forms a setting takes, e.g. ``train_freq``: 4 or [4, "step"]."""


# The settings a run may also override, beyond its algorithm's defaults above, each with
# an example (the library's default) whose type a value must have: SB3's keywords of DQN
# and TD3 that are plain data, and CraftSuite's own (agents/dqn.py, agents/td3.py).
# With the defaults, these are every name ``check_hyperparameters`` accepts.
_OFF_POLICY = dict(tau=1.0, train_freq=OneOf((1, [1, "step"])), gradient_steps=1, n_steps=1,
                   optimize_memory_usage=False, replay_buffer_kwargs={}, stats_window_size=100, device="auto",
                   prioritized=True)
# CraftSuite's DQN settings that take one of a few names, the first SB3's behaviour:
# the loss, what target_update_interval counts, and how the observation reaches the MLP
# (the grid planes as an image: agents/networks.py)
DQN_CHOICES = MappingProxyType({"loss": ("huber", "mse"), "target_update_unit": ("transitions", "gradient_steps"),
                                "features_extractor": ("flatten", "residual-cnn")})
DQN_MORE = MappingProxyType(dict(_OFF_POLICY, max_grad_norm=10.0, double=True, dueling=True, loss="huber",
                                 target_update_unit="transitions", features_extractor="flatten"))
TD3_MORE = MappingProxyType(dict(_OFF_POLICY, tau=0.005, policy_delay=OneOf((2, None)),  # None: the schedule
                                 delay_schedule=[[20_000, 4], [None, 2]]))


# The ranges of the numeric settings, (lowest, highest, whether the lowest itself is out):
# a value outside is refused by name before anything runs. gradient_steps is left out:
# SB3 reads -1 as "as many as the env steps collected".
RANGES = MappingProxyType({
    "learning_rate": (0, None, True), "buffer_size": (1, None, False), "batch_size": (1, None, False),
    "learning_starts": (0, None, False), "gamma": (0, 1, False), "tau": (0, 1, True),
    "target_update_interval": (1, None, False), "exploration_fraction": (0, 1, False),
    "exploration_initial_eps": (0, 1, False), "exploration_final_eps": (0, 1, False),
    "train_freq": (1, None, False), "n_steps": (1, None, False), "stats_window_size": (1, None, False),
    "max_grad_norm": (0, None, True), "target_policy_noise": (0, None, False),
    "target_noise_clip": (0, None, False), "policy_delay": (1, None, False)})


def _out_of_range(name: str, value) -> str | None:
    """What ``value`` of setting ``name`` must be, if it is a number out of its range; else None."""
    if name not in RANGES or isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    low, high, open_low = RANGES[name]
    if (value > low if open_low else value >= low) and (high is None or value <= high):
        return None
    above = f"above {low}" if open_low else f"at least {low}"
    if high is not None:
        return f"{above} and at most {high}" if open_low else f"between {low} and {high}"
    return above


class HyperparameterError(ValueError, TypeError):
    """Hyperparameters that name no setting of their algorithm or hold a value of the wrong
    type. A TypeError too: an unknown keyword was the algorithm constructor's TypeError before
    settings were checked by name, and callers may still catch that."""


def _forms(example) -> tuple[tuple[type, ...], str]:
    """The types a value may have, by the example's, and their description."""
    if isinstance(example, OneOf):
        forms = [_forms(e) for e in example]
        return tuple(t for types, _ in forms for t in types), " or ".join(text for _, text in forms)
    if isinstance(example, bool):
        return (bool,), "true or false"
    if isinstance(example, int):
        return (int,), "an integer"
    if isinstance(example, float):
        return (int, float), "a number"  # 1 stands for 1.0
    if isinstance(example, str):
        return (str,), "a string"
    if isinstance(example, (list, tuple)):
        return (list, tuple), "a list"
    if isinstance(example, dict):
        return (dict, type(None)), "an object (or null)"  # SB3 reads None as no keywords
    if example is None:
        return (type(None),), "null"
    raise TypeError(f"no type rule for the example {example!r}")


def hyperparameter_examples(algorithm: str) -> dict:
    """Every setting ``algorithm`` takes from a run, with an example value of each: its
    CraftSuite default, else the library's."""
    if algorithm not in ALGORITHMS:
        raise KeyError(f"unknown algorithm {algorithm!r}; algorithms: {list(ALGORITHMS)}")
    return {**(TD3_MORE if algorithm == "td3" else DQN_MORE), **(TD3_DEFAULTS if algorithm == "td3" else DQN_DEFAULTS)}


def check_hyperparameters(algorithm: str, overrides: Mapping | None, source: str = "hyperparameters") -> dict:
    """``overrides`` of ``algorithm``'s settings, checked by name and by type before
    anything runs; returned as given. ``source`` names where they came from in the message
    (``--hyper`` on the command line).

    Types follow each setting's example (``hyperparameter_examples``): an integer where it
    is an integer (never true/false), a number (an integer too) where it is a float, true or
    false strictly, a list, an object. Only data is checked (what JSON and run records
    hold): a Python object given to ``make_agent`` (a learning-rate schedule, an
    ``ActionNoise``) is the algorithm constructor's to judge.

    Raises:
        HyperparameterError: an unknown setting (the message lists the valid ones), a
            value of the wrong type, or a number out of its range (``RANGES``); the message
            names the setting and what it takes.
    """
    examples = hyperparameter_examples(algorithm)
    more = TD3_MORE if algorithm == "td3" else DQN_MORE
    overrides = dict(overrides or {})
    unknown = sorted(set(overrides) - set(examples))
    if unknown:
        raise HyperparameterError(f"{source}: {algorithm.upper()} has no setting {', '.join(map(repr, unknown))}; "
                                  f"its settings: {', '.join(sorted(examples))}")
    defaults = TD3_DEFAULTS if algorithm == "td3" else DQN_DEFAULTS
    for name, value in overrides.items():
        if not isinstance(value, _DATA):
            continue
        # a setting of several forms says so in its row of *_MORE, though its default has one
        types, text = _forms(more[name] if isinstance(more.get(name), OneOf) else examples[name])
        example = examples[name][0] if isinstance(examples[name], OneOf) else examples[name]
        # CraftSuite's defaults are what a run gets; the other settings' examples are the
        # library's defaults, which CraftSuite may replace (TD3's policy_delay: its schedule)
        shown = f"default {example!r}" if name in defaults else f"e.g. {example!r}"
        if not isinstance(value, types) or (isinstance(value, bool) and bool not in types):
            raise HyperparameterError(f"{source}: {name} must be {text} ({shown}), got {value!r}")
        bound = _out_of_range(name, value)
        if bound:
            raise HyperparameterError(f"{source}: {name} must be {bound} ({shown}), got {value!r}")
        choices = DQN_CHOICES.get(name) if algorithm == "dqn" else None
        if choices and value not in choices:
            raise HyperparameterError(f"{source}: {name} must be one of {list(choices)}, got {value!r}")
    return overrides


_DATA = (str, int, float, bool, list, tuple, dict, type(None))  # what JSON and a run's record hold


def algorithm_settings(algorithm: str, overrides: Mapping | None = None) -> dict:
    """The keywords ``algorithm`` (``"dqn"`` or ``"td3"``) is built with: its defaults,
    then ``overrides`` (a key replaces the default's whole value), as plain JSON data: what
    a run records as its effective hyperparameters and hashes into its run key.

    Raises:
        HyperparameterError: ``overrides`` name an unknown setting or hold a value of the
            wrong type (``check_hyperparameters``).
    """
    import copy

    overrides = check_hyperparameters(algorithm, overrides)
    settings = copy.deepcopy({**(TD3_DEFAULTS if algorithm == "td3" else DQN_DEFAULTS), **(overrides or {})})
    # fused Adam: one kernel per step instead of a Python loop over the parameters, about
    # 25% more updates per second for these small nets on a CPU (benchmarks/student_throughput.py)
    policy_kwargs = settings["policy_kwargs"] = dict(settings.get("policy_kwargs") or {})
    policy_kwargs["optimizer_kwargs"] = {"fused": True, **policy_kwargs.get("optimizer_kwargs", {})}
    return settings


class MethodError(ValueError):
    """A ``METHODS`` row that cannot run: unknown world, algorithm or target setting."""


@dataclass(frozen=True)
class Method:
    name: str
    world: str  # a world kind of WORLD_KINDS
    algorithm: str  # a key of ALGORITHMS
    product: bool  # the automaton state's one-hot in the observation
    distill: str | None = None  # None, "static" or "dynamic" (needs a teacher's table)
    crm: bool = False  # counterfactual experience over automaton states
    # DistilledTarget keywords over TARGET_DEFAULTS (read-only once the row is built)
    target: Mapping = field(default_factory=dict, hash=False)
    description: str = ""

    def __post_init__(self):
        where = f"METHODS row {self.name!r}"
        if self.world not in WORLD_KINDS:
            raise MethodError(f"{where}: world {self.world!r} does not exist; worlds: {list(WORLD_KINDS)}")
        if ALGORITHMS.get(self.algorithm) != self.world:
            fits = [a for a, w in ALGORITHMS.items() if w == self.world]
            raise MethodError(f"{where}: algorithm {self.algorithm!r} does not run in the {self.world} world; "
                              f"use one of {fits}")
        if self.distill not in DISTILLATIONS:
            raise MethodError(f"{where}: distill must be one of {list(DISTILLATIONS)}, got {self.distill!r}")
        unknown = sorted(set(self.target) - set(TARGET_DEFAULTS))
        if unknown or (self.target and self.distill is None):
            raise MethodError(f"{where}: target takes {sorted(TARGET_DEFAULTS)} and only with distill; "
                              f"got {self.target!r}")
        object.__setattr__(self, "target", MappingProxyType(dict(self.target)))  # a row of a read-only table

    @property
    def needs_table(self) -> bool:
        """Whether the method needs a teacher's table (``craftsuite teacher``)."""
        return self.distill == "dynamic"

    def observes(self, automaton_state: bool | None = None) -> bool:
        """Whether a run of this method sees the automaton state: the row's ``product``, or
        ``automaton_state`` (None: the row's) for a distilled student, whose automaton enters
        through its target whether or not the policy sees the state (the paper's authors'
        students did not).

        Raises:
            MethodError: ``automaton_state`` differs from the row's and the method cannot
                take it, naming both.
        """
        if automaton_state is None or automaton_state == self.product:
            return self.product
        if not isinstance(automaton_state, bool):
            raise MethodError(f"automaton_state must be true, false or null, got {automaton_state!r}")
        if self.distill is not None and not self.crm:
            return automaton_state
        if self.crm:  # distilled or not: its replay writes the one-hot the observation must carry
            why = "its counterfactual experiences relabel the automaton state in the observation"
        elif self.product:
            why = f"the automaton state is what it adds to {_scratch_of(self.world)!r}: run that instead"
        else:
            why = f"a method from scratch sees the world alone: {_product_of(self.world)!r} sees the automaton state"
        free = ", ".join(n for n, m in METHODS.items() if m.distill and not m.crm)
        raise MethodError(f"method {self.name!r} cannot run with automaton_state={automaton_state}: {why}; only "
                          f"the distilled students ({free}) may go with or without it")

    def settings(self) -> dict:
        """What the row makes a run do, as plain data (recorded and hashed with each run)."""
        return {"algorithm": self.algorithm, "product": self.product, "distill": self.distill, "crm": self.crm,
                "target": self.target_kwargs() if self.distill else None}

    def target_kwargs(self, **given) -> dict:
        """The ``DistilledTarget`` keywords: the paper's, then the row's, then ``given``
        (entries of None are left to the row)."""
        return {**TARGET_DEFAULTS, **self.target, **{k: v for k, v in given.items() if v is not None}}


METHODS = MappingProxyType({m.name: m for m in (
    Method("dqn", "Grid", "dqn", False, description="DQN without the automaton state"),
    Method("product-dqn", "Grid", "dqn", True, description="DQN over the product MDP (also the teacher)"),
    Method("crm", "Grid", "dqn", True, crm=True, description="product DQN with counterfactual experiences"),
    Method("static", "Grid", "dqn", True, "static", description="DQN student, statically distilled automaton"),
    Method("dynamic", "Grid", "dqn", True, "dynamic",
           description="DQN student, teacher distilled into the automaton (the paper's method)"),
    # The transfer method: the teacher's values only where the automaton moves, never faded
    # (its self-loop values, ~77 everywhere, are fitted everywhere otherwise and slow the
    # student: experiments/self-loops), and every real step replayed from every automaton
    # state (CRM), so that one touch of an object teaches each edge it would take
    Method("crm-edges", "Grid", "dqn", True, "dynamic", crm=True, target={"rho": 1.0, "self_loops": False},
           description="product DQN with counterfactual experiences and the teacher's values on the "
                       "automaton's edges only, never faded"),
    Method("td3", "Cont", "td3", False, description="TD3 from scratch"),
    Method("product-td3", "Cont", "td3", True, description="TD3 over the product MDP"),
    Method("td3-static", "Cont", "td3", True, "static", description="TD3 student, statically distilled automaton"),
    Method("td3-dynamic", "Cont", "td3", True, "dynamic",
           description="TD3 student, teacher distilled into the automaton (the paper's method)"),
    # the one distilled variant under which a MuJoCo student was measured to learn Blind
    # Craftsman sooner than scratch: the teacher's values only where the automaton moves
    # (its flat self-loop values are fitted everywhere otherwise), never faded
    Method("td3-dynamic-edges", "Cont", "td3", True, "dynamic", target={"rho": 1.0, "self_loops": False},
           description="td3-dynamic with the teacher's values on the automaton's edges only, never faded (rho 1)"),
    Method("td3-crm-edges", "Cont", "td3", True, "dynamic", crm=True, target={"rho": 1.0, "self_loops": False},
           description="td3-dynamic-edges with counterfactual experiences over automaton states (CRM)"),
)})


def methods_for(world: str) -> list[str]:
    """The methods that run in a student world (``Cont``, ``Grid10``, ...), in table order."""
    from .ids import world_kind

    kind = world_kind(world)
    return [name for name, m in METHODS.items() if m.world == kind]


def scratch(world: str) -> str | None:
    """The baseline of a student world: its algorithm from scratch, without the automaton
    (``td3`` in ``Cont``, ``dqn`` on the grids)."""
    from .ids import world_kind

    return _scratch_of(world_kind(world))


def _scratch_of(kind: str) -> str | None:
    return next((n for n, m in METHODS.items() if m.world == kind and not (m.product or m.distill or m.crm)), None)


def _product_of(kind: str) -> str | None:
    return next((n for n, m in METHODS.items() if m.world == kind and m.product and not (m.distill or m.crm)), None)


def check_methods(names) -> None:
    """Raise KeyError naming the unknown methods and the known ones."""
    unknown = [n for n in names if n not in METHODS]
    if unknown:
        raise KeyError(f"unknown method(s) {unknown}; methods: {list(METHODS)}")
