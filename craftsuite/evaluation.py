"""The suites' greedy evaluation as a function, for any agent.

``evaluate(policy, env)`` plays exactly the evaluation a suite's run records in its
``evals.csv``: the suite's number of episodes, on the reset seeds of the evaluation at a
given step (``runs.eval_seed``), in the world as the suite sets it (a Grid10 student's fixed
instance, MuJoCo's settings), each episode a success when the env says the task was
completed (``info["is_success"]`` at its end). The policy may be an SB3 model (or anything
with SB3's ``predict``), a torch module (Q-values or logits: the best action; else the
action itself) or a plain callable ``obs -> action``. What comes back is the success rate,
mean return and mean length, with every episode's record.
"""

from __future__ import annotations

from dataclasses import dataclass

import gymnasium as gym
import numpy as np

from .episodes import Episode, rollout
from .ids import is_id, parse_id
from .runs import eval_seed


@dataclass(frozen=True)
class Evaluation:
    success: float  # the share of episodes that completed the task
    mean_return: float
    mean_length: float  # decisions per episode
    episodes: tuple[Episode, ...] = ()  # each episode's record, in seed order (its reset seed among them)
    env_id: str = ""
    env_kwargs: dict | None = None  # the world's settings beyond its id
    step: int | None = None  # the evaluation's step: its seeds are eval_seed(step) + i


def protocol(env: str, suite: str = "standard", step: int | None = None):
    """The suite's student config behind an evaluation of ``env`` (an id, e.g.
    ``CraftSuite/ToolHome-Cont-v0``): its world settings, episodes and budget; and the
    step whose seeds the evaluation plays (None: the run's last evaluation, at its budget).

    Raises:
        ValueError: not a CraftSuite id, an unknown suite or task (``names.UnknownName``,
            also a KeyError), a task the suite has no budget for, or a suite whose own
            settings are wrong (its learner regime, say); each named with its fix.
    """
    from .methods import scratch
    from .suites import SUITES, suite_named
    from .task_registry import resolve_task

    if not (isinstance(env, str) and is_id(env)):
        parse_id(env)  # its message names the id's form
    chosen = suite_named(suite)
    task, world = parse_id(env)
    spec = resolve_task(task)
    if not chosen.has_budget(spec, world):  # the rung is another suite's
        theirs = [name for name, s in SUITES.items() if s.has_budget(spec, world)]
        theirs = [name for name in theirs if world in SUITES[name].worlds] or theirs  # those running it first
        raise ValueError(f"{task} in {world} is not a rung of the {suite!r} suite, whose protocol (budget, "
                         f"evaluations) an evaluation follows: give suite= one of "
                         + ", ".join(repr(name) for name in theirs or sorted(SUITES)))
    try:
        config = chosen.student_config(spec, world, scratch(world))
    except ValueError as err:  # a setting of the suite's own (its regime, say): not one the caller gave
        raise ValueError(f"suite {suite!r}: {err}") from None
    return config, config.steps if step is None else step


def evaluate(policy, env: str, *, suite: str = "standard", step: int | None = None, episodes: int | None = None,
             product: bool | None = None) -> Evaluation:
    """``policy``'s greedy evaluation on ``env`` (a CraftSuite id) as ``suite``'s records
    hold it: the suite's episodes on the seeds of the evaluation at ``step`` (default: the
    last, at the suite's budget for the rung), in the suite's world. ``episodes`` overrides
    the count; ``product``: whether the policy sees the automaton state (default: as its
    observation space says, else not).

    Raises:
        ValueError: a bad id or suite (``protocol``), or an action outside the env's action
            space, naming the episode, the action and the fix.
    """
    config, step = protocol(env, suite, step)
    n = config.eval_episodes if episodes is None else episodes
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ValueError(f"episodes must be a positive integer, got {n!r}")
    if not isinstance(step, int) or isinstance(step, bool) or step < 0:
        raise ValueError(f"step must be a non-negative integer (the evaluation's transitions), got {step!r}")
    kwargs = config.env_kwargs
    if product is None:
        product = sees_automaton(policy, config.env_id, kwargs)
    played = play(lambda space: _batched(policy, space), config.env_id, kwargs, product, n, eval_seed(step))
    return Evaluation(float(np.mean([e.success for e in played])), float(np.mean([e.total_reward for e in played])),
                      float(np.mean([e.length for e in played])), tuple(played), config.env_id, kwargs, step)


def play(policy_for, env_id: str, env_kwargs: dict, product: bool, episodes: int, seed: int,
         on_step=None) -> list[Episode]:
    """The greedy episodes of an evaluation, the one loop every evaluation of a single policy
    runs (the population engine steps its members' together, on the same seeds): ``episodes``
    fresh envs played side by side on reset seeds ``seed``, ``seed + 1``, ..., so that the
    policy sees one batch per decision. ``policy_for(action_space)`` gives the batch policy;
    ``on_step(episode, reward, info)`` sees every step."""
    envs = [gym.make(env_id, product=product, **env_kwargs) for _ in range(episodes)]
    try:
        return rollout(envs, policy_for(envs[0].action_space), episodes, seed, on_step=on_step)
    finally:
        for env in envs:
            env.close()


def sees_automaton(policy, env_id: str, kwargs: dict) -> bool:
    """Whether a policy that declares its observation space (an SB3 model) was trained
    with the automaton state in its observations.

    Raises:
        ValueError: a space of neither shape (a policy of another world, say), naming both.
    """
    space = getattr(policy, "observation_space", None)
    if space is None:
        return False
    from .wrappers import observation_shapes

    plain = gym.make(env_id, product=False, **kwargs)
    try:
        (shape, product), theirs = observation_shapes(plain), tuple(space.shape)
    finally:
        plain.close()
    if theirs in (shape, product):
        return theirs == product
    raise ValueError(f"the policy observes shape {theirs}, which {env_id}'s observations are not ({shape}, or "
                     f"{product} with the automaton state): was it trained in another world?")


def _batched(policy, space):
    """``policy`` as a function of a batch of observations, its actions checked against ``space``."""
    if hasattr(policy, "predict"):  # SB3's models and policies
        def act(batch):
            return policy.predict(batch, deterministic=True)[0]
    elif _is_module(policy):
        act = _module_policy(policy, space)
    elif callable(policy):
        def act(batch):
            return [policy(obs) for obs in batch]
    else:
        raise ValueError(f"policy must be an SB3 model, a torch module or a callable obs -> action, "
                         f"got {type(policy).__name__}")

    def checked(batch):
        actions = act(batch)
        if np.ndim(actions) == 0 or len(actions) != len(batch):
            raise ValueError(f"the policy returned {actions!r} for a batch of {len(batch)} observations: a batch "
                             "policy (predict, a torch module) returns one action per observation")
        out = []
        for action in actions:
            if hasattr(action, "detach"):  # a torch tensor, maybe still in its graph
                action = action.detach().cpu().numpy()
            raw = np.asarray(action)
            try:
                a = raw.astype(space.dtype)
            except (TypeError, ValueError):  # not a number at all (None, 'up'): the space refuses it below
                a = raw
            else:
                if isinstance(space, gym.spaces.Discrete):
                    a = a.reshape(()) if a.size == 1 else a
                    if raw.size != 1 or raw.reshape(()) != a:  # 2.7 is no move: never cast silently
                        a = raw
            if not space.contains(a):
                raise ValueError(f"the policy returned {raw.tolist()!r}, outside the action space "
                                 f"{space}: return actions in it (clip a continuous output to its bounds)")
            out.append(a)
        return out

    return checked


def _is_module(policy) -> bool:
    try:
        import torch
    except ImportError:  # pragma: no cover - torch is a dependency
        return False
    return isinstance(policy, torch.nn.Module)


def _module_policy(module, space):
    import torch

    device = next(module.parameters(), torch.empty(0)).device

    def act(batch):
        training = module.training
        module.eval()  # evaluated as a policy is: no dropout, no batch statistics updated
        try:
            with torch.no_grad():
                try:
                    out = module(torch.as_tensor(np.asarray(batch), dtype=torch.float32, device=device))
                except RuntimeError as err:  # torch names its tensors' shapes, not the env's observation
                    if isinstance(err, torch.OutOfMemoryError) or not ("shape" in str(err) or "size" in str(err)):
                        raise  # not a mismatch with the observations: the module's own fault, as torch says it
                    raise ValueError(f"the torch module cannot take this env's observations, of shape "
                                     f"{np.shape(batch)[1:]} ({str(err).splitlines()[0]}): give one built for "
                                     "them") from None
        finally:
            module.train(training)
        if not isinstance(out, torch.Tensor):
            raise ValueError(f"the torch module returned {type(out).__name__}, not a tensor of actions or of "
                             "values per action: give a module (or a callable) that returns one")
        out = out.cpu().numpy()
        if isinstance(space, gym.spaces.Discrete) and out.ndim == 2 and out.shape[1] == space.n:
            return out.argmax(axis=1)  # Q-values or logits: the greedy action
        return out

    return act
