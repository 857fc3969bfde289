"""The methods a benchmark compares, as data: one row per method, named for what it does.

``METHODS`` drives the suites (which methods run in which world), the command line's
choices and the leaderboard's legend; ``craftsuite.agents.factory.make_agent`` builds a row
into an agent. This module imports no torch, so listing methods stays cheap.

A row names its world kind (``Grid``: DQN on the grids, ``Cont``: TD3 in the MuJoCo
world), whether the policy sees the automaton state, and how the student uses the
automaton: a distilled target (``static`` or ``dynamic``, with the ``DistilledTarget``
keywords in ``target``), counterfactual experience (``crm``), or potential-based reward
shaping from the automaton's values (``shaping``: ``static`` or ``dynamic``, the potential
solved from the automaton or distilled from a teacher, negated where ``potential_sign`` is
-1; ``craftsuite.shaping``). A variant of a method is a row of its own, never a
hyperparameter of a suite, so a leaderboard row says what ran.
"""

from __future__ import annotations

import numbers
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from .ids import WORLD_KINDS
from .names import UnknownName, unknown_name

# the algorithm family of each world kind: DQN needs discrete moves, TD3 continuous thrust
ALGORITHMS = MappingProxyType({"dqn": "Grid", "td3": "Cont"})
DISTILLATIONS = (None, "static", "dynamic")  # where a distilled target's, or a shaping potential's, values come from
# the DistilledTarget's keywords unless a row or a run says otherwise: the paper's rho,
# and the teacher's values on every label (self-loops included)
TARGET_DEFAULTS = MappingProxyType({"rho": 0.999, "self_loops": True})


def check_target(rho, self_loops) -> None:
    """The distilled target's keywords (``DistilledTarget``'s), each refused by name: a row
    is checked when it is built, not when its first run starts."""
    if isinstance(rho, bool) or not isinstance(rho, numbers.Real) or not 0.0 <= rho <= 1.0:
        raise ValueError(f"rho must be a number in [0, 1], got {rho!r}")
    if not isinstance(self_loops, bool):
        raise ValueError(f"self_loops must be true or false, got {self_loops!r}")


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
    shaping: str | None = None  # None, "static" or "dynamic": the potential of reward shaping
    # Phi = potential_sign * the values: +1 as the baseline was asked for; -1 takes the sign
    # of Toro Icarte et al.'s code (Phi = -V; not its scale or discount). Both keep the optimal
    # policy; they differ in where learning starts (shaping by Phi is an unshaped learner
    # started at Phi: Wiewiora 2003)
    potential_sign: int = 1

    def __post_init__(self):
        where = f"METHODS row {self.name!r}"
        for flag in ("product", "crm"):  # read as truths: "no" would switch one on
            if not isinstance(getattr(self, flag), bool):
                raise MethodError(f"{where}: {flag} must be True or False, got {getattr(self, flag)!r}")
        if self.world not in WORLD_KINDS:
            raise MethodError(f"{where}: world {self.world!r} does not exist; worlds: {', '.join(WORLD_KINDS)}")
        if ALGORITHMS.get(self.algorithm) != self.world:
            fits = [a for a, w in ALGORITHMS.items() if w == self.world]
            raise MethodError(f"{where}: algorithm {self.algorithm!r} does not run in the {self.world} world; "
                              f"use one of {', '.join(fits)}")
        if self.distill not in DISTILLATIONS:
            raise MethodError(f"{where}: distill must be one of {', '.join(map(repr, DISTILLATIONS))}, "
                              f"got {self.distill!r}")
        if self.shaping not in DISTILLATIONS:
            raise MethodError(f"{where}: shaping must be one of {', '.join(map(repr, DISTILLATIONS))}, "
                              f"got {self.shaping!r}")
        if self.shaping and (self.crm or self.distill or not self.product):
            raise MethodError(f"{where}: shaping is a method of its own: with the automaton state, without a "
                              "distilled target or CRM")
        if type(self.potential_sign) is not int or self.potential_sign not in (1, -1) or (
                self.potential_sign == -1 and not self.shaping):  # an int: -1.0 would key its runs apart
            raise MethodError(f"{where}: potential_sign is 1 or -1, and -1 only with shaping; "
                              f"got {self.potential_sign!r}")
        unknown = sorted(set(self.target) - set(TARGET_DEFAULTS))
        if unknown or (self.target and self.distill is None):
            raise MethodError(f"{where}: target takes {', '.join(sorted(TARGET_DEFAULTS))} and only with distill; "
                              f"got {self.target!r}")
        try:
            check_target(**{**TARGET_DEFAULTS, **self.target})
        except ValueError as err:
            raise MethodError(f"{where}: target {err}") from None
        object.__setattr__(self, "target", MappingProxyType(dict(self.target)))  # a row of a read-only table

    @property
    def needs_table(self) -> bool:
        """Whether the method needs a teacher's table (``craftsuite teacher``)."""
        return self.distill == "dynamic" or self.shaping == "dynamic"

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
        elif self.shaping:
            why = "its shaped rewards change with the automaton state, which its policy sees (as the baseline's does)"
        elif self.product:
            why = f"the automaton state is what it adds to {_scratch_of(self.world)!r}: run that instead"
        else:
            why = f"a method from scratch sees the world alone: {_product_of(self.world)!r} sees the automaton state"
        free = ", ".join(n for n, m in METHODS.items() if m.distill and not m.crm)
        raise MethodError(f"method {self.name!r} cannot run with automaton_state={automaton_state}: {why}; only "
                          f"the distilled students ({free}) may go with or without it")

    def settings(self) -> dict:
        """What the row makes a run do, as plain data (recorded and hashed with each run)."""
        out = {"algorithm": self.algorithm, "product": self.product, "distill": self.distill, "crm": self.crm,
               "target": self.target_kwargs() if self.distill else None}
        if self.shaping:  # only where set: a row without it records (and hashes) the four fields alone
            out["shaping"] = self.shaping
        if self.potential_sign != 1:  # likewise: the rows with Phi = V record what they always did
            out["potential_sign"] = self.potential_sign
        return out

    def target_kwargs(self, **given) -> dict:
        """The ``DistilledTarget`` keywords: the paper's, then the row's, then ``given``
        (entries of None are left to the row)."""
        return {**TARGET_DEFAULTS, **self.target, **{k: v for k, v in given.items() if v is not None}}


_ROWS = {m.name: m for m in (
    Method("dqn", "Grid", "dqn", False, description="DQN without the automaton state"),
    Method("product-dqn", "Grid", "dqn", True, description="DQN over the product MDP (also the teacher)"),
    Method("crm", "Grid", "dqn", True, crm=True,
           description="product DQN with counterfactual experiences (where the automaton has one live state "
                       "there is none to add, and its runs are product-dqn's, seed for seed)"),
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
    # The reward-machine literature's shaping baseline (Toro Icarte et al.'s RS): potential-
    # based, so the optimal policy is the unshaped one's; the potential solved from the
    # automaton, or the teacher's distilled values (the paper's knowledge, as shaping)
    Method("rs", "Grid", "dqn", True, shaping="static",
           description="product DQN, rewards shaped by value iteration over the automaton (RS)"),
    Method("dynamic-rs", "Grid", "dqn", True, shaping="dynamic",
           description="product DQN, rewards shaped by the teacher's values distilled into the automaton"),
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
    Method("td3-rs", "Cont", "td3", True, shaping="static",
           description="product TD3, rewards shaped by value iteration over the automaton (RS)"),
    Method("td3-dynamic-rs", "Cont", "td3", True, shaping="dynamic",
           description="product TD3, rewards shaped by the teacher's values distilled into the automaton"),
)}
# the table every module reads: a read-only view of the rows, those registered from outside
# the package included (``register_method``)
METHODS = MappingProxyType(_ROWS)
BUILTIN = tuple(_ROWS)  # the package's own rows, in table order
ENTRY_POINTS = "craftsuite.methods"  # the entry-point group of installed packages' rows
_NAME = re.compile(r"[a-z0-9][a-z0-9.]*(-[a-z0-9.]+)*\Z")  # as the package's rows: lowercase, digits, dashes


def register_method(row: Method) -> None:
    """Add a row from outside the package to ``METHODS`` (as ``gymnasium.register`` adds an
    id): it then runs in the suites, the command line and the leaderboard as the package's
    rows do, trained by CraftSuite's learners with the rules the row names. Registering the
    same row twice is nothing.

    Raises:
        MethodError: not a ``Method``, a name that is not lowercase words joined by dashes,
            or a name taken by another row.
    """
    if not isinstance(row, Method):
        raise MethodError(f"register_method takes a craftsuite.methods.Method row, got {type(row).__name__}")
    if not isinstance(row.name, str) or not _NAME.match(row.name):
        raise MethodError(f"method name {row.name!r}: use lowercase letters, digits and dashes (e.g. td3-rho09), "
                          "as run directories and the command line take it")
    if row.name in _ROWS:
        if _ROWS[row.name] == row:
            return
        raise MethodError(f"method {row.name!r} is a row already ({_ROWS[row.name].description or 'registered'}): "
                          "give yours another name")
    _ROWS[row.name] = row


def resolve_method(text: str) -> str:
    """A method as the command line names it: a row's name, or ``module:name``, which
    imports ``module`` first (where the row registers itself, as gymnasium's
    ``module:Env-v0``). Returns the name.

    Raises:
        KeyError: no such row (after the import), naming the rows there are.
        ValueError: the module cannot be imported, naming it.
    """
    import importlib

    module, sep, name = text.rpartition(":")
    if sep:
        if not module or not name:
            raise ValueError(f"method {text!r}: a method of your own is named module:row (e.g. my_rows:my-td3), "
                             "both parts given")
        try:
            importlib.import_module(module)
        except ImportError as err:
            raise ValueError(f"method {text!r}: module {module!r} cannot be imported ({err}); put it on the "
                             "Python path (PYTHONPATH) or install its package") from None
    try:
        check_methods([name])
    except UnknownName as err:
        if sep:  # imported, and its import registered no such row
            raise UnknownName(f"{err}; module {module!r} was imported and registers no row {name!r}") from None
        raise
    return name


def external_rows() -> list[dict]:
    """The rows registered from outside the package, as plain data (a spawned worker starts
    with the package's rows alone, and registers these: ``register_rows``)."""
    return [{**{f: getattr(row, f) for f in row.__dataclass_fields__}, "target": dict(row.target)}
            for name, row in _ROWS.items() if name not in BUILTIN]


def register_rows(rows: list[dict]) -> None:
    """Register ``external_rows``' rows (in a worker)."""
    for fields in rows:
        register_method(Method(**fields))


def load_entry_points() -> None:
    """Register the rows installed packages declare under the ``craftsuite.methods``
    entry-point group: each entry a ``Method``, a list of them, or a function returning
    them (a package's rows then need no import on the command line)."""
    from importlib.metadata import entry_points

    import warnings

    for point in entry_points(group=ENTRY_POINTS):
        try:
            rows = point.load()
            rows = rows() if callable(rows) and not isinstance(rows, Method) else rows
            for row in [rows] if isinstance(rows, Method) else list(rows):
                register_method(row)
        except Exception as err:  # one package's broken rows never stop CraftSuite: named, and left out
            package = getattr(point.dist, "name", None) or "an installed package"
            warnings.warn(f"{package}'s craftsuite.methods entry point {point.value!r} was not loaded "
                          f"({type(err).__name__}: {err})", stacklevel=2)


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


def is_distilled(method: str) -> bool:
    """Whether a method's student learns with a distilled target (the methods the results
    compare with their world's algorithm from scratch)."""
    return method in METHODS and bool(METHODS[method].distill)


def _scratch_of(kind: str) -> str | None:
    return next((n for n, m in METHODS.items() if m.world == kind and not (m.product or m.distill or m.crm)), None)


def _product_of(kind: str) -> str | None:
    return next((n for n, m in METHODS.items()
                 if m.world == kind and m.product and not (m.distill or m.crm or m.shaping)), None)


def check_methods(names) -> None:
    """Raise UnknownName (a KeyError) naming the unknown methods, the closest known ones and every known one."""
    unknown = [n for n in names if n not in METHODS]
    if unknown:
        raise unknown_name("method", unknown, METHODS, "(a row of your own: module:name, whose module calls "
                           "craftsuite.methods.register_method)")


load_entry_points()
