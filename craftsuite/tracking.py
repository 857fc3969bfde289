"""The objective's automaton, run beside a world: the product MDP's second half.

Every world owns one ``ObjectiveTracker``: it labels nothing itself (that is the
``Labeller``'s job), it takes each step's label mask, advances the automaton, says whether
the episode ends (acceptance or the rejecting sink), pays the completion reward and builds
the automaton part of ``info``.
"""

from __future__ import annotations

from .labelling import Labeller
from .spec import TaskSpec


class ObjectiveTracker:
    def __init__(self, spec: TaskSpec):
        self.automaton = spec.automaton
        self.labeller = Labeller(spec, self.automaton.propositions)
        self.completion_reward = spec.completion_reward
        self.state = self.automaton.initial
        # Python lists: indexing them is several times faster than numpy scalars per step
        self._rows = self.automaton.delta.tolist()
        self._accepting = self.automaton.accepting.tolist()
        self._rejecting = self.automaton.rejecting.tolist()
        self._names: dict[int, tuple[str, ...]] = {}

    def reset(self) -> dict:
        self.state = self.automaton.initial
        return {"labels": (), "label_mask": 0, "automaton_state": self.state,
                "automaton_transition": None, "is_success": False, "violation": False}

    def advance(self, mask: int) -> tuple[float, bool, dict]:
        """Read one label: (completion reward earned, episode over, info)."""
        w = self.state
        w2 = self.state = self._rows[w][mask]
        success, violation = self._accepting[w2], self._rejecting[w2]
        labels = self._names.get(mask)
        if labels is None:
            labels = self._names[mask] = self.labeller.names(mask)
        info = {"labels": labels, "label_mask": mask, "automaton_state": w2,
                "automaton_transition": (w, mask, w2), "is_success": success,
                "violation": violation}
        return (self.completion_reward if success else 0.0), success or violation, info

    @property
    def flag(self) -> str:
        """'accepted', 'violated' or '' for the current state (drawn on frames)."""
        w = self.state
        return "accepted" if self._accepting[w] else "violated" if self._rejecting[w] else ""
