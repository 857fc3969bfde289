"""The ``craftsuite`` command line: ``craftsuite <command> --help`` explains each command."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _tasks(args) -> int:
    from .registration import registered_ids, tasks

    ids = registered_ids()
    for name, spec in tasks().items():
        a = spec.automaton
        states, edges = a.size()
        print(f"{name}: {spec.formula}")
        print(f"  propositions: {', '.join(spec.proposition_names)}")
        print(f"  automaton: {states} states, {edges} transitions (+ rejecting sink: {bool(a.rejecting.any())})")
        for env_id in ids:
            if env_id.split("/")[1].split("-")[0] == name:
                print(f"  {env_id}")
    return 0


def _automaton(args) -> int:
    from .automata import write_image
    from .registration import resolve_task

    spec = resolve_task(args.task)
    if args.describe:
        print(spec.automaton.describe())
    if args.out:
        path = write_image(spec.automaton, args.out, title=f"{spec.name}: {spec.formula}",
                           show_sink=args.show_sink)
        print(f"wrote {path}")
    return 0


def _demo(args) -> int:
    import cv2
    import gymnasium as gym
    import numpy as np
    from tqdm import tqdm

    from .automata import write_image
    from .registration import registered_ids, tasks
    from .scripted import scripted_policy

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ids = [i for i in registered_ids() if args.task in (None, i.split("/")[1].split("-")[0])]
    if not ids:
        print(f"no registered id for task {args.task!r}", file=sys.stderr)
        return 2
    rows = []
    for env_id in tqdm(ids, desc="scripted rollouts", unit="env"):
        env = gym.make(env_id, render_mode="rgb_array")
        policy = scripted_policy(env)
        successes, lengths = 0, []
        for episode in range(args.episodes):
            env.reset(seed=args.seed + episode)
            if episode == 0:
                first = env.render()
            steps, done = 0, False
            while not done:
                _, _, term, trunc, info = env.step(policy(None))
                steps += 1
                done = term or trunc
            if episode == 0:
                last = env.render()
            successes += bool(info["is_success"])
            lengths.append(steps)
        gap = np.full((first.shape[0], 8, 3), 255, np.uint8)
        picture = out / f"{env_id.split('/')[1]}.png"
        cv2.imwrite(str(picture), cv2.cvtColor(np.concatenate([first, gap, last], 1), cv2.COLOR_RGB2BGR))
        rows.append((env_id, successes, args.episodes, float(np.mean(lengths)), picture.name))
        env.close()
    for name, spec in tasks().items():
        try:
            write_image(spec.automaton, out / f"{name}-automaton.png", title=f"{name}: {spec.formula}")
        except RuntimeError as err:  # no Graphviz: keep the DOT text
            print(f"note: {err}", file=sys.stderr)
            write_image(spec.automaton, out / f"{name}-automaton.dot")
    print(f"\n| id | scripted successes | mean steps | picture (start, end) |\n|---|---|---|---|")
    for env_id, ok, n, steps, pic in rows:
        print(f"| {env_id} | {ok}/{n} | {steps:.1f} | {out / pic} |")
    print(f"\nautomata drawn in {out}/<Task>-automaton.png")
    cont = [i for i in ids if "-Cont-" in i]
    if cont:
        from .rollouts import record_video

        rec = record_video(cont[0], "scripted", 1, str(out / f"{cont[0].split('/')[1]}.mp4"), args.seed)
        print(f"rollout video: {rec.path} ({rec.frames} frames, {rec.codec})")
    return 0


def _video(args) -> int:
    from . import registration  # noqa: F401  (registers the ids)
    from .rollouts import record_video

    rec = record_video(args.env_id, args.policy, args.episodes, args.out, args.seed, args.fps, args.product)
    print(f"wrote {rec.path}: {rec.frames} frames at {rec.fps} fps ({rec.codec}); "
          f"{rec.successes}/{rec.episodes} episodes completed the objective")
    return 0


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="craftsuite", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("tasks", help="list the tasks, their formulas, automata and gymnasium ids")
    p.set_defaults(run=_tasks)

    p = sub.add_parser("automaton", help="draw or print a task's automaton")
    p.add_argument("task", help="task name, e.g. BlindCraftsman")
    p.add_argument("--out", help="image file (.png, .svg, .pdf or .dot)")
    p.add_argument("--describe", action="store_true", help="print states and guarded transitions")
    p.add_argument("--show-sink", action="store_true", help="also draw the rejecting sink")
    p.set_defaults(run=_automaton)

    p = sub.add_parser("demo", help="roll out the scripted policy on every id; write pictures")
    p.add_argument("--out", default="out/demo", help="output directory (default: out/demo)")
    p.add_argument("--task", help="only this task (default: all)")
    p.add_argument("--episodes", type=_positive, default=10, help="episodes per id (default: 10)")
    p.add_argument("--seed", type=int, default=0, help="first seed (default: 0)")
    p.set_defaults(run=_demo)

    p = sub.add_parser("video", help="record rollouts of a policy as an MP4 (grid and MuJoCo ids)")
    p.add_argument("env_id", help="a registered id, e.g. CraftSuite/BlindCraftsman-Cont-v0")
    p.add_argument("--policy", default="scripted",
                   help="'random', 'scripted' (default) or a stable-baselines3 checkpoint (.zip)")
    p.add_argument("--episodes", type=_positive, default=1, help="episodes to record (default: 1)")
    p.add_argument("--out", default="rollout.mp4", help="output .mp4 (default: rollout.mp4)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (default: 0)")
    p.add_argument("--fps", type=float, help="frames per second (default: the env's render_fps)")
    p.add_argument("--product", action="store_true",
                   help="make the env with product=True (for checkpoints trained on the product MDP)")
    p.set_defaults(run=_video)
    return parser


def gym_error():
    import gymnasium as gym

    return gym.error.Error


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except BrokenPipeError:  # output piped into `head` and the like
        return 0
    except (KeyError, ValueError, RuntimeError, FileNotFoundError, gym_error()) as err:
        print(f"craftsuite {args.command}: error: {err.args[0] if isinstance(err, KeyError) else err}",
              file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
