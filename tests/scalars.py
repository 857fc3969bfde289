"""What a run's TensorBoard log shows, read as TensorBoard reads it (the trainers' tests)."""

from __future__ import annotations


def scalar_steps(log_dir) -> dict[str, list[int]]:
    """Each TensorBoard scalar's steps, as TensorBoard shows them (purges applied)."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    events = EventAccumulator(str(log_dir))
    events.Reload()
    return {tag: [e.step for e in events.Scalars(tag)] for tag in events.Tags()["scalars"]}


def hparams_sessions(log_dir) -> list[dict]:
    """The HParams sessions TensorBoard shows for a run: one dict per session start."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator
    from tensorboard.plugins.hparams import plugin_data_pb2

    events = EventAccumulator(str(log_dir))
    events.Reload()
    out = []
    for content in events.PluginTagToContent("hparams").values():
        data = plugin_data_pb2.HParamsPluginData.FromString(content)
        if data.HasField("session_start_info"):
            out.append({k: v.number_value if v.HasField("number_value") else
                        v.bool_value if v.HasField("bool_value") else v.string_value
                        for k, v in data.session_start_info.hparams.items()})
    return out
