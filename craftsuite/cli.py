"""The ``craftsuite`` command line: ``craftsuite <command> --help`` explains each command."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .files import EMPTY_PATH

TIME_LIMIT_STATUS = 3  # the exit status of a transfer its --time-limit stopped: runs are left to resume


def _task(argument: str, world: str | None = None) -> str:
    """A task argument's task name: a known task's, or a spec file's (``*.toml``, read and
    registered here, with its ids). Called before anything is written. ``world``: how the
    command picks a world (e.g. ``the world with --world``), said where an id was given.

    Raises:
        UnknownName: an unknown task name (a KeyError), listing the closest and the known ones.
        SpecError: a spec file that is missing or cannot be used.
        ValueError: an id (or something shaped like one) where a task goes.
    """
    from .ids import NAMESPACE, parse_id
    from .registration import register_task
    from .task_registry import is_spec_file, resolve_task

    if str(argument).startswith(f"{NAMESPACE}/"):  # an id where a task goes: not a path to look for
        task, _ = parse_id(argument)  # a malformed one: the id format, named
        raise ValueError(f"{argument} is an id; give its task ({task})" + (f" and {world}" if world else ""))
    if is_spec_file(argument):
        return parse_id(register_task(Path(argument))[0])[0]
    return resolve_task(argument).name


def _registered(task: str, world: str) -> str:
    """The id of a known task in a world, or a ValueError naming the task's worlds."""
    import gymnasium as gym

    from .ids import env_id, parse_id
    from .registration import registered_ids

    name = env_id(task, world)
    if name not in gym.registry:
        worlds = [parse_id(i)[1] for i in registered_ids() if parse_id(i)[0] == task]
        raise ValueError(f"task {task!r} has no {world} world; its worlds: {', '.join(worlds)}")
    return name


def _world(text: str) -> str:
    """``--world``: Cont, Kinematic or Grid<size> (argparse names a bad one at once)."""
    from .ids import world_kind

    try:
        world_kind(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None
    return text


def _known_worlds() -> list[str]:
    """The worlds of the known tasks: Cont, Kinematic, then the grids by size."""
    from .ids import CONT_WORLDS, grid_world
    from .task_registry import tasks

    return [*CONT_WORLDS] + [grid_world(n) for n in sorted({n for spec in tasks().values() for n in spec.grid.sizes})]


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Every option's help ends with its default, unless it already names it or has none."""

    def _get_help_string(self, action):
        text = action.help or ""
        # `is`, not `in`: 0 == False, and a default of 0 is one to show
        if "default" in text or action.default is None or action.default is False or action.default in (
                (), argparse.SUPPRESS):
            return text
        return super()._get_help_string(action)


def _records(args) -> int:
    from .files import file_to_write
    from .record_format import markdown, write_markdown

    if args.markdown:
        file_to_write(args.markdown, "--markdown", "records.md")
        print(f"wrote {write_markdown(args.markdown)}")
    else:
        print(markdown())
    return 0


def _tasks(args) -> int:
    from .ids import parse_id
    from .registration import registered_ids
    from .task_registry import ladder

    if args.markdown:
        from .files import file_to_write
        from .references import write_tasks_page

        if args.tag:
            raise ValueError("--markdown writes the page of every rung; --tag selects rungs to list: "
                             "use one or the other")
        file_to_write(args.markdown, "--markdown", "tasks.md")  # before minutes of rollouts
        path = write_tasks_page(args.markdown, episodes=args.episodes)
        print(f"wrote {path}")
        return 0
    ids = registered_ids()
    for spec in ladder(*args.tag):
        a = spec.automaton
        states, edges = a.size()
        print(f"{spec.name} [{', '.join(spec.tags)}]: {spec.formula}")
        print(f"  propositions: {', '.join(spec.proposition_names)}")
        print(f"  automaton: {states} states, {edges} transitions (+ rejecting sink: {bool(a.rejecting.any())})")
        for env_id in ids:
            if parse_id(env_id)[0] == spec.name:
                print(f"  {env_id}")
    return 0


def _automaton(args) -> int:
    from .automata import image_format, write_image
    from .files import file_to_write
    from .task_registry import resolve_task

    if args.out is None and not args.describe:
        raise ValueError("give --out FILE to draw the automaton, --describe to print its states and edges, or both")
    if args.out is not None:
        file_to_write(args.out, "--out", f"{args.task}.png")
        image_format(args.out)
    spec = resolve_task(args.task)
    if args.describe:
        print(spec.automaton.describe())
    if args.out is not None:
        path = write_image(spec.automaton, args.out, title=f"{spec.name}: {spec.formula}",
                           show_sink=args.show_sink)
        print(f"wrote {path}")
    return 0


def _scripted(args) -> int:
    import cv2
    import gymnasium as gym
    import numpy as np

    from .automata import write_image
    from .files import directory_to_write
    from .ids import CONT, file_stem, parse_id
    from .progress import progress_iter
    from .registration import registered_ids
    from .episodes import rollout
    from .scripted import scripted_policy
    from .task_registry import tasks

    ids = [i for i in registered_ids() if args.task in (None, parse_id(i)[0])]
    out = directory_to_write(args.out, "--out")
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for env_id in progress_iter(ids, "scripted rollouts", "env"):
        env = gym.make(env_id, render_mode="rgb_array", status_panel=True)  # pictures for people: inventory shown
        policy = scripted_policy(env)
        frames = []  # the first episode's start and end
        played = rollout(env, policy, 1, args.seed, on_reset=lambda _: frames.append(env.render()))
        frames.append(env.render())
        played += rollout(env, policy, args.episodes - 1, args.seed + 1)
        first, last = frames
        successes, lengths = sum(e.success for e in played), [e.length for e in played]
        gap = np.full((first.shape[0], 8, 3), 255, np.uint8)
        picture = out / f"{file_stem(env_id)}.png"
        cv2.imwrite(str(picture), cv2.cvtColor(np.concatenate([first, gap, last], 1), cv2.COLOR_RGB2BGR))
        rows.append((env_id, successes, args.episodes, float(np.mean(lengths)), picture.name))
        env.close()
    for name, spec in tasks().items():
        if args.task not in (None, name):
            continue
        try:
            write_image(spec.automaton, out / f"{name}-automaton.png", title=f"{name}: {spec.formula}")
        except RuntimeError as err:  # no Graphviz: keep the DOT text
            print(f"note: {err}", file=sys.stderr)
            write_image(spec.automaton, out / f"{name}-automaton.dot")
    print("\n| id | scripted successes | mean steps | picture (start, end) |\n|---|---|---|---|")
    for env_id, ok, n, steps, pic in rows:
        print(f"| {env_id} | {ok}/{n} | {steps:.1f} | {out / pic} |")
    print(f"\nautomata drawn in {out}/<Task>-automaton.png")
    cont = [i for i in ids if parse_id(i)[1] == CONT]
    if cont:
        from .rollouts import record_video

        rec = record_video(cont[0], "scripted", 1, str(out / f"{file_stem(cont[0])}.mp4"), args.seed,
                           env_kwargs={"status_panel": True})
        print(f"rollout video: {rec.path} ({rec.frames} frames, {rec.codec})")
    return 0


def _video(args) -> int:
    from .files import file_to_write
    from .ids import is_id, parse_id
    from .rendering.video import check_video_path
    from .rollouts import record_video
    from .task_registry import resolve_task

    file_to_write(args.out, "--out", "rollout.mp4")  # where it writes, before a minute of rollouts
    try:
        check_video_path(args.out)
    except ValueError as err:
        raise ValueError(f"--out {err}") from None
    if is_id(args.target):
        if args.world is not None:
            raise ValueError(f"--world picks the world of a task; {args.target} is an id, which names its own")
        task, world = parse_id(args.target)
        # an unregistered id: its task or its world named as elsewhere, not gymnasium's guess
        env_id = _registered(resolve_task(task).name, world)
    else:
        env_id = _registered(_task(args.target), args.world or "Cont")
    env = _world_kwargs(args.env, parse_id(env_id)[1])
    # a video is for people: show the inventory and automaton state unless --env says otherwise
    rec = record_video(env_id, args.policy, args.episodes, args.out, args.seed, args.fps, args.product or None,
                       env_kwargs={"status_panel": True, **env})
    print(f"wrote {rec.path}: {rec.frames} frames at {rec.fps} fps ({rec.codec}); "
          f"{rec.successes}/{rec.episodes} episodes completed the objective")
    return 0


def _json_object(text: str | None, flag: str = "--hyper", example: str = '{"learning_rate": 1e-4}') -> dict:
    if not text:
        return {}
    try:
        value = json.loads(text)
    except json.JSONDecodeError as err:
        raise ValueError(f"{flag} is not JSON ({err}): {text!r}") from None
    if not isinstance(value, dict):
        raise ValueError(f"{flag} must be a JSON object, e.g. '{example}', not {text!r}")
    return value


def _world_kwargs(text: str | None, world: str, flag: str = "--env") -> dict:
    """``flag``'s JSON, gymnasium.make keywords checked against ``world``'s before anything runs."""
    from .registration import check_world_kwargs

    value = _json_object(text, flag, '{"max_episode_steps": 500}')  # (a keyword of every world)
    check_world_kwargs(world, value, flag)
    return value


def _hyper(text: str | None, algorithm: str, flag: str = "--hyper") -> dict:
    """``flag``'s JSON, checked by name and type against ``algorithm``'s settings before anything runs."""
    from .hyperparameters import check_hyperparameters

    return check_hyperparameters(algorithm, _json_object(text, flag), source=flag)


def _teacher(args) -> int:
    from .configs import TeacherConfig
    from .files import directory_to_write
    from .runs import read_result, teacher_outcome
    from .training import train_teacher

    directory_to_write(args.out, "--out")
    config = TeacherConfig(task=args.task, size=args.size,
                           layout_seed=None if args.layout_seed < 0 else args.layout_seed,
                           seed=args.seed, max_steps=args.max_steps, target_success=args.target_success,
                           eval_every=args.eval_every, eval_episodes=args.eval_episodes,
                           hyperparameters=_hyper(args.hyper, "dqn"), n_envs=args.n_envs, engine=args.engine)
    path = train_teacher(config, args.out, device=args.device)
    print((path / "result.json").read_text().strip())
    result = read_result(path)
    print(f"teacher run: {path}: {teacher_outcome(result, config.target_success)}")
    if not result["reached_target"]:
        print(f"  its table distils what it learned so far; for a teacher at its target give it more than "
              f"--max-steps {config.max_steps:,}")
    print(f"  teacher: {path / 'teacher.zip'}\n  dynamic table: {path / 'table.npz'}")
    return 0


def _distill(args) -> int:
    from .agents.distillation import static_distillation
    from .automata import image_format
    from .files import file_to_write
    from .task_registry import resolve_task

    file_to_write(args.out, "--out", "table.npz")  # where it writes, before it distils
    if args.draw:
        image_format(args.draw)
        file_to_write(args.draw, "--draw", "values.png")
    if args.static:
        _unread(args, f"with --static the task is SOURCE ({args.source}) and no teacher is read")
        if (Path(args.source) / "config.json").is_file():  # a run directory: the teacher, not a task
            raise ValueError(f"{args.source} is a run directory: --static distils a task's automaton alone; give the "
                             "task's name, or leave out --static to distil this teacher's values")
        spec = resolve_task(_task(args.source))
        table = static_distillation(spec.automaton, completion_reward=spec.completion_reward)
        automaton = spec.automaton
    else:
        from .agents.factory import distill_from_replay, load_agent

        source = Path(args.source)
        if not source.exists():
            try:  # a task's name: its automaton alone is distilled statically
                task = _task(args.source)
            except (KeyError, ValueError):
                raise FileNotFoundError(f"no teacher at {source}: give a teacher run directory or its .zip "
                                        "(dynamic), or a task name with --static") from None
            raise ValueError(f"{args.source} is a task: distil its automaton alone with --static (craftsuite "
                             f"distill {task} --static --out {args.out}), or give a teacher run directory for its "
                             "teacher's values")
        if source.is_dir():  # a teacher run directory: its config names the env, its checkpoint the replay
            from .configs import TeacherConfig
            from .runs import RunDir, load_config

            if not (source / "config.json").is_file():
                raise FileNotFoundError(f"{source} is not a teacher run directory (no config.json)")
            _unread(args, f"{source} is a teacher run directory: its config names the task and env, its checkpoint "
                          "the replay")
            config = load_config(TeacherConfig, source)
            if config.engine == "population":
                from .population.teacher import distill_run

                table, automaton = distill_run(source)
                return _write_table(table, automaton, args)
            env_id, env_kwargs = config.env_id, config.env_kwargs
            saved = RunDir(source, config).last_checkpoint()
            if saved is None:
                raise FileNotFoundError(f"{source} has no checkpoint (model and replay buffer) yet")
            model, replay = saved / "model.zip", saved / "replay.pkl"
        else:
            from .agents.factory import saved_agent_file

            if args.env_id is not None and args.task is not None:
                raise ValueError(f"--task {args.task} --env-id {args.env_id}: the env id names the teacher's task "
                                 "too; give one of them")
            if source.suffix == ".npz":  # (a zip too)
                raise ValueError(f"{source} is a distilled table already: give it to a student (--table), or give "
                                 "its teacher's run directory to distil it again")
            try:  # before its replay is asked for
                saved_agent_file(source)
            except ValueError:
                raise ValueError(f"{source} is not a teacher: give a teacher run directory or its model .zip "
                                 "(dynamic), or a task name with --static") from None
            env_id, env_kwargs = args.env_id or _registered(args.task or "BlindCraftsman", "Grid7"), {}
            model, replay = source, Path(args.replay) if args.replay else None
        if replay is None or not replay.is_file():
            raise FileNotFoundError(f"dynamic distillation needs the teacher's replay buffer: "
                                    f"{replay or 'pass --replay'} (or a teacher run directory)")
        from stable_baselines3.common.env_util import make_vec_env

        teacher = load_agent(model, env=make_vec_env(env_id, n_envs=1, env_kwargs={"product": True, **env_kwargs}))
        teacher.load_replay_buffer(replay)
        table = distill_from_replay(teacher)
        automaton = teacher.get_env().envs[0].unwrapped.automaton
    return _write_table(table, automaton, args)


def _table_methods() -> str:
    """The methods that distil a teacher's table, as the student command names them."""
    from .methods import METHODS

    return ", ".join(m for m, row in METHODS.items() if row.needs_table)


def _unread(args, why: str) -> None:
    """Refuse the flags of a teacher .zip where SOURCE answers them (given, they were ignored)."""
    given = [flag for flag, value in (("--task", args.task), ("--env-id", args.env_id), ("--replay", args.replay))
             if value is not None]
    if given:
        raise ValueError(f"{', '.join(given)}: {why}; leave {'it' if len(given) == 1 else 'them'} out")


def _write_table(table, automaton, args) -> int:
    table.check_finite()  # (before the drawing: a refused table leaves no drawing behind)
    if args.draw:  # drawn first: a failed drawing leaves no table behind either
        from .automata import write_image

        values = table.edge_values(automaton)
        unseen = {e for e in automaton.edges() if e not in values}
        drawn = write_image(automaton, args.draw, title=f"{table.kind} distillation: {automaton.formula}",
                            edge_notes={e: f"{v:.1f}" for e, v in values.items()}, dotted=unseen)
    table.save(args.out)
    print(table.describe(automaton))
    print(f"wrote {args.out}")
    if args.draw:
        print(f"drew {drawn}")
    return 0


def _student(args) -> int:
    from .configs import StudentConfig
    from .files import directory_to_write
    from .methods import METHODS, resolve_method
    from .suite_runner import check_trains
    from .training import train_student

    args.method = resolve_method(args.method)  # a row of the user's own (module:name): its module registers it

    config = StudentConfig(task=args.task, method=args.method, world=args.world, seed=args.seed, steps=args.steps,
                           table=str(Path(args.table).resolve()) if args.table else None, eval_every=args.eval_every,
                           eval_episodes=args.eval_episodes,
                           hyperparameters=_hyper(args.hyper, METHODS[args.method].algorithm),
                           layout_seed=args.layout_seed, world_kwargs=_world_kwargs(args.env, args.world),
                           n_envs=args.n_envs, automaton_state=args.automaton_state, engine=args.engine)
    if METHODS[args.method].needs_table and not args.table:
        raise ValueError(f"method {args.method!r} needs --table (a teacher's table.npz: craftsuite teacher)")
    if args.table and not METHODS[args.method].needs_table:  # it would be recorded, and change the run key
        raise ValueError(f"method {args.method!r} distils no teacher's table: leave out --table (the methods that "
                         f"take one: {_table_methods()})")
    check_trains(config, f"{config.task}'s {config.method} student ({config.world})")  # as a transfer does
    directory_to_write(args.out, "--out")
    path = train_student(config, args.out, device=args.device)
    print((path / "result.json").read_text().strip())
    print(f"student run: {path}")
    return 0


def _transfer(args) -> int:
    import dataclasses

    from .ids import CONT, KINEMATIC, world_kind
    from .methods import resolve_method
    from .provenance import command_line
    from .suite_runner import TimeLimitReached, WorkerLost, transfer
    from .suites import suite_named

    suite = registered = suite_named(args.suite)
    if args.tags is not None or args.tasks is not None:  # the rungs given replace the suite's
        suite = dataclasses.replace(suite, tags=tuple(args.tags or ()),
                                    tasks=tuple(_task(t, "the worlds with --worlds") for t in args.tasks or ()))
    changes = {k: v for k, v in (("worlds", tuple(args.worlds) if args.worlds else None), ("seeds", args.seeds),
                                 ("student_steps", args.steps),
                                 # a row of the user's own (module:name) is registered by its module's import
                                 ("methods", tuple(map(resolve_method, args.methods)) if args.methods else None),
                                 ("teacher_max_steps", args.teacher_steps), ("eval_every", args.eval_every))
               if v is not None}
    if args.seeds is not None:  # every cell that many, the rungs the suite gives more seeds too
        changes["rung_seeds"] = {}
    worlds = list(changes.get("worlds", suite.worlds))
    if args.env and CONT not in worlds:
        raise ValueError(f"--env sets the MuJoCo students' world ({CONT}); these worlds have none: {worlds}")
    if args.td3_hyper and not any(world_kind(w) == CONT for w in worlds):
        raise ValueError(f"--td3-hyper sets the TD3 students (continuous worlds); these worlds have none: {worlds}")
    if args.dqn_hyper is not None:
        dqn = _hyper(args.dqn_hyper, "dqn", "--dqn-hyper")
        changes["dqn_overrides"] = {**suite.dqn_overrides, **dqn}
        changes["teacher_hyperparameters"] = {**suite.teacher_hyperparameters, **dqn}
    if args.env is not None:
        changes["cont_world_kwargs"] = _world_kwargs(args.env, CONT)
    if args.board_size is not None:
        if KINEMATIC not in worlds:
            raise ValueError(f"--board-size sets the kinematic board ({KINEMATIC}); these worlds have none: {worlds}")
        changes["kinematic_world_kwargs"] = {} if args.board_size == 7 else {"size": args.board_size}
    if args.td3_hyper is not None:
        changes["td3_overrides"] = {**suite.td3_overrides, **_hyper(args.td3_hyper, "td3", "--td3-hyper")}
    if args.engine is not None:
        changes["engine"] = args.engine
    if args.regime is not None:  # another regime's runs never pool with the suite's: they may share its archive
        changes["regime"] = args.regime
    suite = dataclasses.replace(suite, **changes)
    out = args.out or f"runs/{args.suite}"
    if args.archive and args.no_archive:
        raise ValueError("--archive DIR keeps the runs in that archive, --no-archive keeps none: give one or neither")
    # a run whose settings differ from the suite's (a budget, a setting) goes to the archive only
    # when asked for: a smoke test would otherwise sit beside the suite's runs as a variant
    settings = {"student_steps", "teacher_max_steps", "eval_every", "dqn_overrides", "teacher_hyperparameters",
                "cont_world_kwargs", "kinematic_world_kwargs", "td3_overrides", "engine"}
    # and a rung, world or method the suite does not run would be filed under a suite it is not part of
    beyond = ({s.name for s in suite.rungs()} - {s.name for s in registered.rungs()}
              or set(suite.worlds) - set(registered.worlds) or set(suite.methods) - set(registered.methods))
    own = suite.archived and not settings & set(changes) and not beyond
    archive = None if args.no_archive or not (args.archive or own) else (args.archive or "results")
    notes = []  # said under the suite's line, which transfer says once it has checked its input
    if suite.archived and not own and archive is None and not args.no_archive:
        notes.append(f"({'rungs, worlds or methods' if beyond else 'settings'} beyond the suite's: no results archive "
                     "unless --archive DIR is given)")

    if args.dry_run:
        from .suite_runner import plan

        suite_line, *rest = plan(suite, out, archive=archive, device=args.device).lines()
        for line in [suite_line, *notes, *rest]:  # the notes under the suite's line, as a run says them
            print(line)
        return 0

    def log(line: str) -> None:
        print(line)
        while notes:
            print(notes.pop(0))
    try:
        result = transfer(suite, out, workers=args.workers, ray=args.ray, video=not args.no_video, log=log,
                          command=command_line(), device=args.device, archive=archive, members=args.members,
                          time_limit=None if args.time_limit is None else args.time_limit * 60)
    except TimeLimitReached as stopped:
        print(f"{stopped}; the finished runs are in {out}" + (f" and kept in {Path(archive) / suite.name}"
                                                             if archive else ""))
        return TIME_LIMIT_STATUS
    except WorkerLost as lost:  # not a refused command (2): its status says a signal, as a killed process's would
        print(f"craftsuite transfer: error: {lost}", file=sys.stderr)
        return lost.status
    print(f"leaderboard: {result.leaderboard} (and .csv)")
    for plot in result.plots:
        print(f"learning curves: {plot}")
    if result.video:
        print(f"video of the best student: {result.video}")
    return 0


def _archive(args) -> int:
    from .archive import add, scan, size
    from .files import directory_to_write
    from .provenance import command_line, read, record_session, start_session
    from .suites import suite_named

    suite = suite_named(args.suite)
    session = start_session(command_line())
    directory_to_write(args.archive, "--archive")
    archive = directory_to_write(Path(args.archive) / args.suite, "--archive")
    read(archive)  # a damaged provenance.json there, named before anything is kept
    # every source read and checked before anything is kept: a refused command leaves the archive as it was
    sources = [scan(source, suite) for source in args.runs]
    for source in sources:
        for reason in source.skipped:
            print(f"skipped {reason}")
    usable = sum(len(runs) for source in sources for runs in source.runs.values())
    if not usable:
        raise ValueError(f"no run under {', '.join(args.runs)} can be archived in suite {args.suite}: each is "
                         "named above with why; give finished runs of that suite")
    kept = {"teachers": 0, "students": 0}
    for source in sources:
        more = add(source, archive)
        kept = {k: kept[k] + more[k] for k in kept}
    if any(kept.values()):
        record_session(archive, {**session, "archived": kept}, 0.0)
    there = usable - sum(kept.values())
    print(f"kept {kept['students']} student runs and {kept['teachers']} teachers in {archive} "
          + (f"({there} held there already; " if there else "(") + f"{size(archive) / 1e6:.1f} MB in all)")
    return 0


def _leaderboard(args) -> int:
    from .files import directory_to_write, file_to_write
    from .reporting.pages import write_leaderboard, write_results_page
    from .reporting.board import build
    from .reporting.plots import draw_curves, save_figures
    from .methods import resolve_method
    from .reporting.sources import read_runs

    for method in args.methods or ():  # a row of the user's own: its module registers it
        if ":" not in method:
            raise ValueError(f"--methods {method}: name a row of your own as module:name (CraftSuite's rows are "
                             "known already)")
        resolve_method(method)
    narrowed = args.tasks is not None or args.worlds is not None
    if narrowed and (args.page or args.reproduction):
        raise ValueError("--tasks and --worlds narrow a leaderboard; a page (--page, --reproduction) shows every run "
                         "of its directories: leave them out")
    tasks = None if args.tasks is None else {_task(t, "the worlds with --worlds") for t in args.tasks}
    if args.reproduction:
        if args.page or args.out or len(args.runs) > 1:
            raise ValueError("--reproduction writes one page from one transfer directory: give one RUNS, "
                             "without --page or --out")
        from .reproduction import write_report

        file_to_write(args.reproduction, "--reproduction", "reproduction.md")
        print(f"wrote {write_report(args.runs[0], args.reproduction)}")
        return 0
    if args.page:
        if args.out:
            raise ValueError("--page writes the page and its images beside PATH; --out is for one directory's "
                             "leaderboard: use one or the other")
        file_to_write(args.page, "--page", "results.md")
        path = write_results_page(args.runs, args.page)
        print(f"wrote {path}")
        return 0
    if len(args.runs) > 1 and not args.out:  # never written into one of them (an archive, maybe)
        raise ValueError("several run directories are one leaderboard: give --out DIR for it")
    if narrowed and not args.out:  # never over the directory's own board of every run
        raise ValueError("--tasks and --worlds make a board of some of the runs: give --out DIR for it")
    if args.out:
        directory_to_write(args.out, "--out")
    # several directories are one board: a user's runs beside the archive's, on the same rungs;
    # one directory of a suite sets its runs at budgets the suite no longer asks for apart
    def keep(config: dict) -> bool:  # a run's config read alone: the logs of the others are never read
        return (tasks is None or config.get("task") in tasks) and (args.worlds is None
                                                                   or config.get("world") in args.worlds)

    only = " of " + " ".join(f"{flag} {' '.join(values)}" for flag, values in (("--tasks", args.tasks),
                                                                             ("--worlds", args.worlds)) if values)
    # narrowed, one of several directories may hold none of those runs (an archive without the
    # user's rung): the board they make together must hold some
    runs = [read_runs(d, suite_cells=len(args.runs) == 1, keep=keep if narrowed else None,
                      only=only if narrowed else "", required=not narrowed or len(args.runs) == 1)
            for d in args.runs]
    board = runs[0].board if len(runs) == 1 else build(*(r.students for r in runs), keep=keep if narrowed else None)
    if narrowed and len(runs) > 1 and not board.entries:
        raise ValueError(f"no finished student runs{only} under {', '.join(str(r.students) for r in runs)}")
    out = Path(args.out or runs[0].path)
    curves = draw_curves(board)  # drawn before the leaderboard is written: a failure leaves no part of it
    path = write_leaderboard(board, out)
    plots = save_figures(curves, out)
    print(path.read_text())
    print(f"wrote {path}, {out / 'leaderboard.csv'}, {out / 'seeds.csv'}" + "".join(f", {p}" for p in plots))
    return 0


def _path(text: str) -> str:
    """A path flag's text: never empty (an empty path is the working directory to Python,
    which no one typing ``--out ''``, or ``--out "$UNSET"``, meant)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(EMPTY_PATH)
    return text


_path.__name__ = "path"


def _source(text: str) -> str:
    """distill's SOURCE: a path flag's text (never empty) whose message names both of its kinds."""
    try:
        return _path(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError("is empty: give a teacher run directory or its .zip, or with --static a "
                                         "task name") from None


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


_positive.__name__ = "integer"  # argparse names a non-integer "invalid integer value"


def _positive_float(text: str) -> float:
    value = float(text)
    if not 0 < value < float("inf"):  # nan and inf are no rate either
        raise argparse.ArgumentTypeError(f"must be a number above 0, got {text}")
    return value


_positive_float.__name__ = "number"  # argparse names a non-number "invalid number value"


def _seed(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more (seeds are non-negative), got {value}")
    return value


_seed.__name__ = "seed"  # argparse names a non-integer "invalid seed value"


def _fraction(text: str) -> float:
    value = float(text)
    if not 0 <= value <= 1:
        raise argparse.ArgumentTypeError(f"must be between 0 and 1, got {value}")
    return value


_fraction.__name__ = "number"  # argparse names a non-number "invalid number value"


def _on_off(text: str) -> bool:
    if text not in ("on", "off"):
        raise argparse.ArgumentTypeError(f"must be on or off, got {text!r}")
    return text == "on"


class _CommandParser(argparse.ArgumentParser):
    """A command's parser: defaults in its help, and ``--debug`` after the command too."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **{"formatter_class": _HelpFormatter, **kwargs})
        self.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=DEBUG_HELP)

    def add_argument(self, *args, **kwargs):
        if "help" not in kwargs and kwargs.get("default") is not None:  # (a help text of its own says more)
            kwargs["help"] = "(default: %(default)s)"
        return super().add_argument(*args, **kwargs)


DEBUG_HELP = "on an error, show the full traceback instead of one line"


def build_parser() -> argparse.ArgumentParser:
    from . import __version__
    from .configs import DEFAULT_ENGINE, ENGINES
    from .methods import METHODS
    from .regimes import REGIMES
    from .suites import SUITES
    from .task_registry import SPEC_SUFFIX, ladder

    engine_help = (f"what trains the run: {DEFAULT_ENGINE} (default; the population engine, here a population of "
                   "one); sb3 (one SB3 agent per run, as CraftSuite trained before) only reuses a finished run")

    parser = argparse.ArgumentParser(prog="craftsuite", formatter_class=_HelpFormatter,
                                     description="CraftSuite's command line: craftsuite COMMAND --help explains each "
                                                 "command.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("--debug", action="store_true", help=DEBUG_HELP)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_CommandParser)

    def command(name: str, help: str) -> argparse.ArgumentParser:  # its line in the list, atop its own --help too
        return sub.add_parser(name, help=help, description=help[0].upper() + help[1:].replace("%%", "%") + ".")

    methods = ", ".join(METHODS)
    names = ", ".join(s.name for s in ladder())
    task_help = f"a task: {names}; or a task spec file (path/to/task{SPEC_SUFFIX}), registered for this command"
    worlds = ", ".join(_known_worlds())

    p = command("records", "the run record format (config, result, evaluations, episodes)")
    p.add_argument("--markdown", type=_path, metavar="PATH",
                   help="write it as a docs page to PATH, e.g. docs/records.md")
    p.set_defaults(run=_records)

    p = command("tasks", "list the tasks (the ladder's rungs, easiest first), formulas, automata, ids")
    p.add_argument("--tag", nargs="+", default=(), help="only the tasks with any of these tags: "
                   + ", ".join(sorted({t for spec in ladder() for t in spec.tags})))
    p.add_argument("--markdown", type=_path, metavar="PATH",
                   help="write the tasks page (specs, automata, scripted and random "
                   "references) to PATH instead, e.g. docs/tasks.md")
    p.add_argument("--episodes", type=_positive, default=100,
                   help="episodes per id for the references of --markdown (default: 100)")
    p.set_defaults(run=_tasks)

    p = command("automaton", "draw or print a task's automaton")
    p.add_argument("task", help=task_help)
    p.add_argument("--out", type=_path, help="image file (.png, .svg, .pdf or .dot)")
    p.add_argument("--describe", action="store_true", help="print states and guarded transitions")
    p.add_argument("--show-sink", action="store_true", help="also draw the rejecting sink")
    p.set_defaults(run=_automaton)

    p = command("scripted", "roll out the scripted policy on every id; write pictures")
    p.add_argument("--out", type=_path, default="out/scripted", help="output directory (default: out/scripted)")
    p.add_argument("--task", help=f"only this task (default: all): {task_help}")
    p.add_argument("--episodes", type=_positive, default=10, help="episodes per id (default: 10)")
    p.add_argument("--seed", type=_seed, default=0, help="first seed (default: 0)")
    p.set_defaults(run=_scripted)

    p = command("teacher", "train a grid DQN teacher until 90%% greedy success; distil it")
    p.add_argument("task", help=task_help)
    p.add_argument("--out", type=_path, default="runs/teachers", help="runs directory (default: runs/teachers)")
    p.add_argument("--size", type=int, default=7, help="grid size (default: 7)")
    p.add_argument("--layout-seed", type=int, default=0, help="the fixed grid instance (-1: a new one per episode)")
    p.add_argument("--seed", type=_seed, default=0)
    p.add_argument("--max-steps", type=_positive, default=300_000, help="give up after this many steps")
    p.add_argument("--target-success", type=_fraction, default=0.9, help="stop at this greedy success (default: 0.9)")
    p.add_argument("--eval-every", type=_positive, default=5_000)
    p.add_argument("--eval-episodes", type=_positive, default=50)
    p.add_argument("--hyper", help="JSON overrides of the DQN settings, e.g. '{\"learning_rate\": 1e-3}'")
    p.add_argument("--n-envs", type=_positive, default=1,
                   help="envs stepped side by side; each agent step collects one transition from each (default: 1)")
    p.add_argument("--engine", choices=ENGINES, default=DEFAULT_ENGINE, help=engine_help)
    p.add_argument("--device", default="cpu", help="the population engine's torch device: cpu (default) or cuda")
    p.set_defaults(run=_teacher)

    p = command("distill", "distil a teacher (dynamic) or a task's automaton (static) into a table")
    p.add_argument("source", type=_source,
                   help="a teacher run directory or teacher .zip (dynamic), or a task name (--static)")
    p.add_argument("--out", type=_path, required=True, help="the table to write (.npz)")
    p.add_argument("--static", action="store_true", help="value iteration over the automaton alone")
    p.add_argument("--replay", type=_path, help="the teacher's replay buffer (.pkl), when SOURCE is a .zip")
    p.add_argument("--task", help=f"the teacher's task, when SOURCE is a .zip (default: BlindCraftsman): {task_help}")
    p.add_argument("--env-id", help="the teacher's env id (default: CraftSuite/<task>-Grid7-v0)")
    p.add_argument("--draw", type=_path,
                   help="also draw the values on the automaton (.png/.svg/.dot; unseen edges dotted)")
    p.set_defaults(run=_distill)

    p = command("student", "train one student or baseline run (any method, one seed)")
    p.add_argument("task", help=task_help)
    p.add_argument("--method", default="td3-dynamic", metavar="METHOD",
                   help=f"one of {methods} (craftsuite.methods.METHODS; default: td3-dynamic), or module:name, a "
                   "row the module registers (craftsuite.methods.register_method)")
    p.add_argument("--world", default="Cont", type=_world,
                   help=f"Cont (MuJoCo), Kinematic or Grid<size>, a world of the task; the known tasks': {worlds}")
    p.add_argument("--table", type=_path,
                   help="a teacher's table.npz (craftsuite teacher), for the methods that distil one: "
                   + _table_methods())
    p.add_argument("--out", type=_path, default="runs/students", help="runs directory (default: runs/students)")
    p.add_argument("--seed", type=_seed, default=0)
    p.add_argument("--steps", type=_positive, default=20_000, help="the budget in transitions (default: 20000)")
    p.add_argument("--n-envs", type=_positive, default=1,
                   help="envs stepped side by side; each agent step collects one transition from each (default: 1)")
    p.add_argument("--eval-every", type=_positive, default=2_000)
    p.add_argument("--eval-episodes", type=_positive, default=10)
    p.add_argument("--hyper", help="JSON overrides of the algorithm's settings, e.g. "
                   "'{\"action_noise\": {\"type\": \"persistent\", \"sigma\": 0.6, \"resample\": 0.1}}'")
    p.add_argument("--env", help="JSON gymnasium.make keywords beyond the registered world, e.g. the "
                   "fine-control MuJoCo world '{\"frame_skip\": 2, \"max_episode_steps\": 1000}'")
    p.add_argument("--layout-seed", type=_seed, help="grid worlds: one fixed instance (default: a new one per episode)")
    p.add_argument("--engine", choices=ENGINES, default=DEFAULT_ENGINE, help=engine_help)
    p.add_argument("--automaton-state", type=_on_off, metavar="on|off",
                   help="whether a distilled student sees the automaton state (default: as its method; the paper's "
                   "authors' students did not)")
    p.add_argument("--device", default="cpu", help="the population engine's torch device: cpu (default) or cuda")
    p.set_defaults(run=_student)

    p = command("transfer", "a suite end to end: teacher, distillation, students, leaderboard, video")
    p.add_argument("--suite", default="quick", help="; ".join(f"{n}: {s.description}" for n, s in SUITES.items()))
    p.add_argument("--out", type=_path, help="output directory (default: runs/<suite>, so suites never share one)")
    p.add_argument("--tags", nargs="+", help="override the suite's rungs: the tasks with any of these tags: "
                   + ", ".join(sorted({t for spec in ladder() for t in spec.tags})))
    p.add_argument("--tasks", nargs="+", help=f"override the suite's rungs: these tasks (with --tags: and these), "
                   f"each {task_help}")
    p.add_argument("--worlds", nargs="+", choices=_known_worlds(),
                   help="override the student worlds (Cont, Kinematic: TD3 methods; Grid10, Grid7: DQN methods)")
    p.add_argument("--methods", nargs="+", metavar="METHOD",
                   help=f"override the suite's methods: any of {methods}, or module:name (a row of your own)")
    p.add_argument("--seeds", type=_positive, help="override the number of seeds: every cell this many, the "
                   "rungs the suite gives more seeds too")
    p.add_argument("--steps", type=_positive, help="one student budget for every rung (transitions)")
    p.add_argument("--teacher-steps", type=_positive, help="override the teacher's step limit")
    p.add_argument("--eval-every", type=_positive, help="override the students' evaluation interval (transitions; "
                   "default: the suite's, or a 20th of each budget)")
    p.add_argument("--env", help="JSON gymnasium.make keywords of the MuJoCo students' world (replaces the suite's), "
                   "e.g. '{\"frame_skip\": 2, \"max_episode_steps\": 1000}'; the leaderboard names them")
    p.add_argument("--board-size", type=int, choices=(7, 10), help="the kinematic board's side (default 7; the "
                   "authors' distilled Blind Craftsman student ran on 10)")
    p.add_argument("--td3-hyper", help="JSON overrides of the TD3 students' settings, merged over the suite's, e.g. "
                   "'{\"action_noise\": {\"type\": \"persistent\", \"sigma\": 0.6, \"resample\": 0.1}}'")
    p.add_argument("--dqn-hyper", help="JSON overrides of the DQN settings of the grid students and the teachers, "
                   "merged over the suite's, e.g. '{\"features_extractor\": \"flatten\"}'")
    p.add_argument("--workers", type=_positive, help="parallel local processes (default: one per core)")
    p.add_argument("--members", type=_positive, help="at most this many seeds of a cell trained as one population "
                   "(default: all of them; the seeds still to train are grouped first, finished ones train "
                   "nothing); smaller populations finish sooner and more run at once, for many cores; "
                   "the processes sharing one GPU take turns on it, so there fewer, larger populations (e.g. 80) "
                   "should use it better (experiments/fresh-seeds); a member's replay grows to 1.1-1.4 GiB by 1M "
                   "transitions on Diamond Mine (less on smaller tasks), and a transfer warns before it trains "
                   "where the populations at once (--workers) would hold more than the memory available")
    p.add_argument("--ray", metavar="ADDRESS", help="run the students on Ray ('local' starts one here)")
    p.add_argument("--no-video", action="store_true", help="skip the rollout video of the best student")
    p.add_argument("--dry-run", action="store_true", help="say what it would train (per cell: the seeds finished "
                   "in --out or the results archive, which are reused, and the transitions left) and stop: the "
                   "suite, settings and directories checked as a run checks them, nothing trained or written")
    p.add_argument("--time-limit", type=_positive_float, metavar="MINUTES",
                   help="stop training after this many minutes (a campaign's part, a machine held for a while): the "
                   "runs still training are stopped and resume from their checkpoints when the same command runs "
                   f"again, the finished ones are kept; exits with status {TIME_LIMIT_STATUS} when it stopped any")
    p.add_argument("--archive", type=_path, metavar="DIR",
                   help="the results archive: runs found in DIR/<suite> are not trained "
                   "again, and every finished run's records are kept there as its population finishes (default: "
                   "results, for the suites that keep their runs: all but quick)")
    p.add_argument("--no-archive", action="store_true", help="neither read nor write a results archive")
    p.add_argument("--engine", choices=ENGINES, help="what trains the teachers and students: population (each "
                   "cell's seeds in one process); sb3 (one SB3 agent per run, as CraftSuite trained before) only "
                   "reuses finished runs, from --out or the archive; default: the suite's")
    p.add_argument("--regime", choices=list(REGIMES), help="the students' learner regime (craftsuite.regimes: "
                   "n-step returns and the like, for every method alike); default: the suite's")
    p.add_argument("--device", help="the population engine's torch device: cpu (default) or cuda")
    p.set_defaults(run=_transfer)

    p = command("archive", "keep finished runs' records in the results archive (results/<suite>)")
    p.add_argument("runs", type=_path, nargs="+", help="transfer output directories, or directories of student runs")
    p.add_argument("--suite", required=True, help="the suite they are runs of: they are kept in its archive (a run "
                   "of a task, world or method it does not run is skipped, named)")
    p.add_argument("--archive", type=_path, default="results", help="the archive (default: results)")
    p.set_defaults(run=_archive)

    p = command("leaderboard", "leaderboard (Markdown, CSV) and learning curves from run directories")
    p.add_argument("runs", type=_path, nargs="+",
                   help="a transfer output directory, or a directory of student runs; several "
                   "are one leaderboard (e.g. your runs from craftsuite.Recorder beside results/standard), or, with "
                   "--page, a section each")
    p.add_argument("--out", type=_path, help="where to write (default: RUNS, if one)")
    p.add_argument("--page", type=_path, metavar="PATH",
                   help="write a results page (Markdown with provenance, tables, plots) "
                   "from the RUNS directories to PATH, e.g. docs/results.md")
    p.add_argument("--reproduction", type=_path, metavar="PATH",
                   help="write the paper's Figure 5 panels, each beside the "
                   "paper's claim, from one transfer directory (craftsuite transfer --suite paper)")
    p.add_argument("--methods", nargs="+", metavar="MODULE:ROW", help="method rows of your own that runs were "
                   "trained with (as transfer's --methods my_module:my-row): read as the methods they are "
                   "(compared with scratch where distilled, described in the legend)")
    p.add_argument("--tasks", nargs="+", metavar="TASK", help=f"the runs of these tasks alone (the others' logs are "
                   f"not read: a board of one rung over an archive in seconds), each {task_help}")
    p.add_argument("--worlds", nargs="+", choices=_known_worlds(), help="the runs in these worlds alone")
    p.set_defaults(run=_leaderboard)

    p = command("video", "record rollouts of a policy as an MP4 (any world of a task)")
    p.add_argument("target", metavar="TASK_OR_ID", help=f"{task_help}, in --world; or a registered id, e.g. "
                   "CraftSuite/BlindCraftsman-Cont-v0")
    p.add_argument("--world", type=_world, help="the task's world: Cont (default), Kinematic or Grid<size>")
    p.add_argument("--policy", default="scripted",
                   help="'random', 'scripted' (default) or a stable-baselines3 checkpoint (.zip)")
    p.add_argument("--episodes", type=_positive, default=1, help="episodes to record (default: 1)")
    p.add_argument("--out", type=_path, default="rollout.mp4", help="output .mp4 (default: rollout.mp4)")
    p.add_argument("--seed", type=_seed, default=0, help="seed of the first episode (default: 0)")
    p.add_argument("--fps", type=_positive_float, help="frames per second (default: the world's pace, the env's "
                   "render_fps decisions a second; continuous worlds' motion is drawn between decisions)")
    p.add_argument("--product", action="store_true",
                   help="make the env with product=True, its observations carrying the automaton state "
                        "(default: as the checkpoint was trained; not for random and scripted)")
    p.add_argument("--env", help="JSON gymnasium.make keywords, e.g. '{\"frame_skip\": 2}' "
                   "(the world the checkpoint was trained in)")
    p.set_defaults(run=_video)
    return parser


def gym_error():
    import gymnasium as gym

    return gym.error.Error


def _check_task(args) -> None:
    """A command's task (a name, or a spec file registered now) and its world, known good
    before the command writes anything: ``args.task`` becomes the task's name."""
    from .ids import grid_world

    if getattr(args, "task", None) is None:
        return
    args.task = _task(args.task, {"student": "the world with --world",
                                  "teacher": "the grid's side with --size (e.g. --size 10)"}.get(args.command))
    if getattr(args, "world", None) is not None:  # student
        _registered(args.task, args.world)
    elif args.command == "teacher":
        _registered(args.task, grid_world(args.size))


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        _check_task(args)
        return args.run(args)
    except BrokenPipeError:  # output piped into `head` and the like
        return 0
    # OSError: a path that cannot be read or written (missing, a file where a folder must be, no permission)
    except (KeyError, ValueError, TypeError, RuntimeError, OSError, gym_error()) as err:
        if args.debug:
            raise
        print(f"craftsuite {args.command}: error: {err.args[0] if isinstance(err, KeyError) else err}",
              file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
