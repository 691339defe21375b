"""TensorBoard event files of a sweep: scalars and hparams per model, resume-safe like ``metrics.csv``."""

import dataclasses
import struct

import numpy as np
import pytest
from tensorboardX.proto import event_pb2, plugin_hparams_pb2

from pushjax import train
from pushjax.train import convergence, metrics_log
from tests.tiny_configs import TINY_SMOKE

CONFIG = dataclasses.replace(TINY_SMOKE, num_steps=6, log_every=1, checkpoint_every=3)


class Killed(Exception):
    pass


def _events(run):
    """The events of a TensorBoard run as TensorBoard reads them: files in name order, a session START with a step
    dropping what came before at that step and later."""
    events = []
    for path in sorted(run.glob("events.out.tfevents.*")):
        data = path.read_bytes()
        offset = 0
        while offset < len(data):
            (length,) = struct.unpack("<Q", data[offset:offset + 8])
            event = event_pb2.Event.FromString(data[offset + 12:offset + 12 + length])
            offset += 12 + length + 4
            if event.session_log.status == event_pb2.SessionLog.START:
                events = [kept for kept in events if kept.step < event.step]
            events.append(event)
    return events


def _scalar_events(run):
    """[((tag, step), value)] in the order TensorBoard reads them; a step written twice appears twice."""
    return [((value.tag, event.step), value.simple_value) for event in _events(run) for value in event.summary.value
            if value.HasField("simple_value")]


def _scalars(run):
    return dict(_scalar_events(run))


@pytest.fixture(scope="module")
def uninterrupted(examples, tmp_path_factory):
    workdir = tmp_path_factory.mktemp("full")
    specs = train.subset_specs(len(examples["motion"]), [20, 40], [0])
    train.sweep(CONFIG, examples, specs, workdir, mode="sequential", progress=False)
    return workdir, specs


def test_every_model_has_its_scalars_and_hparams(uninterrupted):
    workdir, specs = uninterrupted
    for spec in specs:
        run = workdir / "tensorboard" / spec.name / "train"
        scalars = _scalars(run)
        assert {step for tag, step in scalars if tag == "loss"} == set(range(1, 7))
        assert all(scalars[("steps_per_second", step)] > 0 for step in range(1, 7))
        plugin_data = [plugin_hparams_pb2.HParamsPluginData.FromString(value.metadata.plugin_data.content)
                       for event in _events(run) for value in event.summary.value
                       if value.metadata.plugin_data.plugin_name == "hparams"]
        session, = [data for data in plugin_data if data.HasField("session_start_info")]
        assert [info.name.tag for data in plugin_data for info in data.experiment.metric_infos] == ["loss"]
        assert session.session_start_info.hparams["learning_rate"].number_value == pytest.approx(CONFIG.learning_rate)
        assert session.session_start_info.hparams["train_size"].number_value == len(spec.train_indices)
        assert session.session_start_info.hparams["model.head_features"].string_value == str(CONFIG.model.head_features)


def test_a_killed_and_resumed_sweep_shows_the_uninterrupted_scalars(uninterrupted, examples, tmp_path):
    full, specs = uninterrupted

    def kill_at_step_5(step, metrics):
        if step == 5:
            raise Killed

    with pytest.raises(Killed):
        train.sweep(CONFIG, examples, specs, tmp_path, mode="sequential", progress=False, step_callback=kill_at_step_5)
    train.sweep(CONFIG, examples, specs, tmp_path, mode="sequential", progress=False)
    for spec in specs:
        resumed = sorted(item for item in _scalar_events(tmp_path / "tensorboard" / spec.name / "train")
                         if item[0][0] != "steps_per_second")
        expected = sorted(item for item in _scalar_events(full / "tensorboard" / spec.name / "train")
                          if item[0][0] != "steps_per_second")
        assert [key for key, _ in resumed] == [key for key, _ in expected]  # steps 4 and 5 once, though logged twice
        np.testing.assert_allclose([value for _, value in resumed], [value for _, value in expected], rtol=1e-6)


def test_a_model_trained_to_convergence_logs_its_validation_scores(examples, tmp_path):
    spec, = train.subset_specs(len(examples["motion"]), [20], [0])
    criterion = convergence.Criterion(eval_every=2, window=2, base_steps=4, steps_per_example=0, max_steps=4,
                                      min_decay_steps=1)
    trained = train.sweep(CONFIG, examples, [spec], tmp_path, mode="sequential", progress=False, criterion=criterion,
                          validation=examples)
    scalars = _scalars(tmp_path / metrics_log.TENSORBOARD_DIR / spec.name / "train")
    assert [step for step, _, _ in trained.phases.validation] == sorted(
        step for tag, step in scalars if tag == "validation/score")
    for step, trans, rot in trained.phases.validation:
        assert scalars[("validation/trans_percent", step)] == pytest.approx(trans, rel=1e-6)
        assert scalars[("validation/rot_percent", step)] == pytest.approx(rot, rel=1e-6)
