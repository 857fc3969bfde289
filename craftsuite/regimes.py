"""Learner regimes as data: the learning settings a suite gives every student of an
algorithm, on top of its collection regime (envs per update, batch, network, noise).

A ``Regime`` row names what it changes from the algorithms' defaults (n-step returns,
say); a suite names its regime and applies the row to every method's settings, so a
distilled student and the scratch student it is compared with learn by the same rule. The
regime a record ran under is read back from the settings it recorded (``regime_of``), not
from a label: a run whose settings match no row is named by its own settings, and two
regimes' runs are never pooled on a leaderboard.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .hyperparameters import hyperparameter_examples
from .names import look_up


@dataclass(frozen=True)
class Regime:
    name: str
    description: str
    # settings of each algorithm (``craftsuite.hyperparameters``), beyond the suite's
    # collection regime; a setting a row leaves out is the algorithm's default
    td3: dict = field(default_factory=dict)
    dqn: dict = field(default_factory=dict)

    def settings(self, algorithm: str) -> dict:
        return dict(self.td3 if algorithm == "td3" else self.dqn)


REGIMES = {r.name: r for r in (
    Regime("one-step", "one-step TD targets (the quick, transfer and paper suites' regime; the standard and "
           "hard suites' until the learner-regime experiment)"),
    # experiments/learner-regime, wave 1: n = 3 beat one-step for TD3 in MuJoCo (IQM of AUC
    # from scratch 0.46 against 0.15) and for DQN on Grid10 (0.88 against 0.65); n = 5 did
    # not beat n = 3 for TD3
    Regime("n-step", "3-step TD targets (experiments/learner-regime, wave 1)",
           td3={"n_steps": 3}, dqn={"n_steps": 3}),
    # waves 2-3: at n = 3, [256, 256] networks beat [64, 64] for both learners (TD3 IQM of
    # AUC 0.73 against 0.52, DQN 0.93 against 0.84) and LayerNorm helped DQN (0.94) but not
    # TD3 (0.51); Gaussian exploration noise and fewer DQN updates did not help. The
    # standard and hard suites' regime.
    Regime("n-step-wide", "3-step TD targets, [256, 256] networks, LayerNorm in DQN's "
           "(experiments/learner-regime, waves 1-3)",
           td3={"n_steps": 3, "policy_kwargs": {"net_arch": [256, 256]}},
           dqn={"n_steps": 3, "layer_norm": True, "policy_kwargs": {"net_arch": [256, 256]}}),
)}

# Every row fixes the TD targets' length (one step where it says nothing); its other
# settings tell it apart only where it sets them (a run of the one-step regime may have any
# network the suite gave it).
FIXED = ("n_steps",)

# what tells the regimes apart: every setting some row sets
FACTORS = sorted({*FIXED, *(name for r in REGIMES.values() for name in (*r.td3, *r.dqn))})


def _value(algorithm: str, settings: dict, name: str):
    """A setting as a run with ``settings`` (its overrides) trains with it."""
    if name in settings:
        return settings[name]
    example = hyperparameter_examples(algorithm)[name]
    return example[0] if isinstance(example, tuple) else example


def regime_of(algorithm: str, settings: dict) -> str:
    """The name of the regime a run of ``algorithm`` with these settings (the overrides
    its record holds) trained under: the row that fits them (its TD-target length and every
    setting it sets), the one setting most where several fit; a run that fits no row is
    named by its own values of the regimes' settings, e.g. ``n_steps=5``."""
    mine = {name: _value(algorithm, settings, name) for name in FACTORS}
    fits = [regime for regime in REGIMES.values()
            if all(mine[name] == _value(algorithm, regime.settings(algorithm), name)
                   for name in {*FIXED, *regime.settings(algorithm)})]
    if fits:
        return max(fits, key=lambda regime: len(regime.settings(algorithm))).name
    default = {name: _value(algorithm, {}, name) for name in FACTORS}
    return ", ".join(f"{name}={mine[name]!r}" for name in FACTORS if mine[name] != default[name])


def order(name: str) -> tuple:
    """A regime's place wherever regimes are listed: the table's order, then any other
    (a run's own settings, a self-reported learner) by name."""
    names = list(REGIMES)
    return (names.index(name) if name in names else len(names), name)


def check_regime(name: str) -> Regime:
    """The learner regime called ``name``.

    Raises:
        UnknownName: no such regime (a KeyError and a ValueError), naming the regimes.
    """
    return look_up(REGIMES, name, "learner regime")


def describe(name: str) -> str:
    """A regime as a page names it: the row's description, or, for a run's own settings, that."""
    return REGIMES[name].description if name in REGIMES else f"own settings ({name})"
