"""A population member's TensorBoard log, under the tag names an SB3 run's has.

Each member writes ``tb/run_0`` in its run directory, as an SB3 agent of CraftSuite's
trainer does, with SB3's tags: ``eval/mean_reward``, ``eval/mean_ep_length`` and
``eval/success_rate`` at each evaluation, ``rollout/ep_rew_mean``, ``rollout/ep_len_mean``
and ``rollout/success_rate`` (over the last 100 training episodes, SB3's window) as the
logs are written, and the run's settings as an HParams entry, once per run. A member
resumed from a checkpoint starts a new session at its step: TensorBoard then drops what
the killed session logged after it, as the CSV logs are trimmed.
"""

from __future__ import annotations

from collections import deque

from ..runs import EVAL_METRICS, hparams

WINDOW = 100  # SB3's stats_window_size: the training episodes its rollout/ means average


class Scalars:
    def __init__(self, run, step: int):
        from torch.utils.tensorboard import SummaryWriter
        from torch.utils.tensorboard.summary import hparams as hparams_summary

        log_dir = run.path / "tb" / "run_0"
        started = log_dir.is_dir() and any(log_dir.glob("events.out.tfevents.*"))
        # resumed: drop what came after the checkpoint; a fresh start over a killed one's log: drop it all
        purge = step + 1 if step > 0 else (0 if started else None)
        self.writer = SummaryWriter(str(log_dir), purge_step=purge)
        self.window: deque = deque(maxlen=WINDOW)
        if step == 0:  # once per run: a resumed run's first session logged them
            for summary in hparams_summary(hparams(run.config), dict(EVAL_METRICS)):
                self.writer.file_writer.add_summary(summary)

    def episodes(self, rows: list[dict], step: int) -> None:
        """Training episodes as the run's log records them, and the window's means at ``step``."""
        self.window.extend((r["return"], r["length"], r["success"]) for r in rows)
        if rows and self.window:
            n = len(self.window)
            for i, tag in enumerate(("rollout/ep_rew_mean", "rollout/ep_len_mean", "rollout/success_rate")):
                self.writer.add_scalar(tag, sum(e[i] for e in self.window) / n, step)

    def evaluation(self, step: int, success: float, mean_return: float, mean_length: float) -> None:
        self.writer.add_scalar("eval/mean_reward", mean_return, step)
        self.writer.add_scalar("eval/mean_ep_length", mean_length, step)
        self.writer.add_scalar("eval/success_rate", success, step)
        self.writer.flush()

    def close(self) -> None:
        self.writer.close()
