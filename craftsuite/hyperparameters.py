"""The settings of each algorithm a method runs (``dqn``, ``td3``), as data: CraftSuite's
defaults, the other settings a run may override, and the checks of a run's overrides by
name and type before anything runs. ``algorithm_settings`` is what a run records and
hashes into its run key. This module imports no torch, so checking settings stays cheap.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType

from .methods import ALGORITHMS
from .names import suggested, unknown_name

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
# TD3's actor delay, ((until_step, delay), ..., (None, delay)): CraftSuite's default, the
# schedule the paper's text describes (the actor updated after every 4th critic update for
# the first 20,000 steps, then every 2nd, SB3's constant); the authors' code delays by 2
# throughout, as the ``paper`` suite does. AutomatonTD3 runs it unless a run gives
# ``delay_schedule`` or a constant ``policy_delay``.
TD3_DELAY_SCHEDULE = ((20_000, 4), (None, 2))


class OneOf(tuple):
    """Examples of the forms a setting takes, e.g. ``train_freq``: 4 or [4, "step"]."""


# The settings a run may also override, beyond its algorithm's defaults above, each with
# an example (the library's default) whose type a value must have: SB3's keywords of DQN
# and TD3 that are plain data, and CraftSuite's own (agents/dqn.py, agents/td3.py).
# With the defaults, these are every name ``check_hyperparameters`` accepts. None of these
# is merged into a run's settings: a run's key hashes only those it gives.
# layer_norm: LayerNorm (learnable affine) after each hidden Linear layer, before the
# activation, in the value networks only (TD3's critics, DQN's Q-network; their targets too).
_OFF_POLICY = dict(tau=1.0, train_freq=OneOf((1, [1, "step"])), gradient_steps=1, n_steps=1,
                   optimize_memory_usage=False, replay_buffer_kwargs={}, stats_window_size=100, device="auto",
                   prioritized=True, layer_norm=False)
# CraftSuite's DQN settings that take one of a few names, the first SB3's behaviour:
# the loss, what target_update_interval counts, and how the observation reaches the MLP
# (the grid planes as an image: agents/networks.py)
DQN_CHOICES = MappingProxyType({"loss": ("huber", "mse"), "target_update_unit": ("transitions", "gradient_steps"),
                                "features_extractor": ("flatten", "residual-cnn")})
DQN_MORE = MappingProxyType(dict(_OFF_POLICY, max_grad_norm=10.0, double=True, dueling=True, loss="huber",
                                 target_update_unit="transitions", features_extractor="flatten"))
TD3_MORE = MappingProxyType(dict(_OFF_POLICY, tau=0.005, policy_delay=OneOf((2, None)),  # None: the schedule
                                 delay_schedule=[list(row) for row in TD3_DELAY_SCHEDULE]))


# The ranges of the numeric settings, (lowest, highest, whether the lowest itself is out):
# a value outside is refused by name before anything runs. gradient_steps is left out:
# SB3 reads -1 as "as many as the env steps collected". n_steps stops at N_STEPS_MAX: every
# sample reads its n rows, and past it the return is the episode's rest in all but name
# (gamma ** 100 = 0.37 at 0.99; an episode lasts 200 to 1,000 steps).
N_STEPS_MAX = 100
CAPS = frozenset({"max_grad_norm"})  # settings that cap something: Infinity, refused, would mean no cap
RANGES = MappingProxyType({
    "learning_rate": (0, None, True), "buffer_size": (1, None, False), "batch_size": (1, None, False),
    "learning_starts": (0, None, False), "gamma": (0, 1, False), "tau": (0, 1, True),
    "target_update_interval": (1, None, False), "exploration_fraction": (0, 1, False),
    "exploration_initial_eps": (0, 1, False), "exploration_final_eps": (0, 1, False),
    "train_freq": (1, None, False), "n_steps": (1, N_STEPS_MAX, False), "stats_window_size": (1, None, False),
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
    """Hyperparameters that name no setting of their algorithm, hold a value of the wrong
    type or a number out of its range. A TypeError too, as Python's own error for an unknown keyword argument is."""


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
    CraftSuite default, else the library's.

    Raises:
        UnknownName: an algorithm that is not one of ``ALGORITHMS`` (a KeyError and a ValueError).
    """
    if algorithm not in ALGORITHMS:
        raise unknown_name("algorithm", algorithm, ALGORITHMS)
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
        raise HyperparameterError(f"{source}: {algorithm.upper()} has no setting "
                                  f"{', '.join(suggested(k, examples) for k in unknown)}; "
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
        # (JSON's Infinity, 1e400, NaN: Python's too; a record holds JSON, which has none of them)
        if isinstance(value, float) and not math.isfinite(value):
            uncapped = "; a large one, e.g. 1e9, caps nothing" if name in CAPS else ""
            raise HyperparameterError(f"{source}: {name} must be a finite number ({shown}{uncapped}), got {value!r}")
        bound = _out_of_range(name, value)
        if bound:
            raise HyperparameterError(f"{source}: {name} must be {bound} ({shown}), got {value!r}")
        choices = DQN_CHOICES.get(name) if algorithm == "dqn" else None
        if choices and value not in choices:
            raise HyperparameterError(f"{source}: {name} must be one of {', '.join(choices)}, got {value!r}")
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
