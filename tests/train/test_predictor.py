"""`load_model`: a sweep's checkpoint -> a predictor that matches the trained model on dataset examples."""

import dataclasses

import numpy as np
import pytest

from pushjax import train
from pushjax.data import configs as data_configs
from pushjax.data.examples import make_camera
from pushjax.train import evaluate
from pushjax.train.checkpoint import Checkpointer
from pushjax.train.predictor import load_model
from tests.tiny_configs import TINY_SMOKE

CONFIG = dataclasses.replace(TINY_SMOKE, num_steps=2, checkpoint_every=2)
CAMERA = make_camera(data_configs.get_config("data_efficiency", "smoke"))


@pytest.fixture(scope="module")
def trained(examples, tmp_path_factory):
    """A run's work directory with one hybrid sweep of two models, and the sweep's result."""
    run = tmp_path_factory.mktemp("run")
    specs = train.subset_specs(len(examples["motion"]), [20], [0, 1])
    result = train.sweep(CONFIG, examples, specs, run / "train" / "l1" / "hybrid", mode="sequential", progress=False)
    return run, result


def _push_arguments(examples, indices):
    return (examples["depth"][indices], examples["pusher_pos"][indices], examples["action"][indices], CAMERA,
            examples["l"][indices], examples["mu"][indices])


def test_loaded_model_predicts_as_the_trained_one(trained, examples):
    run, result = trained
    predictor = load_model(run, model="size=20/seed=1")
    assert (predictor.name, predictor.variant, predictor.checkpoint[1]) == ("size=20/seed=1", "hybrid", 2)
    assert predictor.config == CONFIG.model
    indices = np.arange(6)
    expected = evaluate.predict(result.model, result.model_state(1), {k: v[indices] for k, v in examples.items()}, 8)
    prediction = predictor(*_push_arguments(examples, indices))
    np.testing.assert_allclose(prediction.motion, expected["motion"], rtol=1e-4, atol=1e-7)
    np.testing.assert_allclose(prediction.object_pos, expected["object_pos"], rtol=1e-4, atol=1e-7)
    np.testing.assert_allclose(prediction.contact, expected["contact"], rtol=1e-4, atol=1e-7)
    np.testing.assert_allclose(np.linalg.norm(prediction.normal, axis=-1), 1.0, rtol=1e-5)
    assert prediction.contact_probability.shape == (6,)
    single = predictor(*_push_arguments(examples, 0))
    assert single.motion.shape == (3,)
    np.testing.assert_allclose(single.motion, prediction.motion[0], rtol=1e-4, atol=1e-7)


def test_load_model_reads_without_writing_and_names_what_is_wrong(trained, tmp_path):
    run, _ = trained
    before = sorted((path, path.stat().st_mtime_ns) for path in run.rglob("*"))
    assert load_model(run / "train" / "l1" / "hybrid" / "checkpoints", model=-1).name == "size=20/seed=1"
    assert sorted((path, path.stat().st_mtime_ns) for path in run.rglob("*")) == before
    with pytest.raises(ValueError, match=r"model: expected an index in \[-2, 2\) or one of"):
        load_model(run, model="size=99/seed=0")
    with pytest.raises(ValueError, match="step: .* steps \\[2\\], not 7"):
        load_model(run, step=7)
    with pytest.raises(ValueError, match="found none"):
        load_model(tmp_path)

    old = Checkpointer(tmp_path / "old" / "checkpoints")
    old.save(5, {"params": {"w": np.zeros((1, 2), np.float32)}}, {"identity": {"names": ["size=1/seed=0"]}})
    old.close()
    with pytest.raises(ValueError, match="has no model_config, model_variants in its metadata") as error:
        load_model(tmp_path / "old")
    assert "\n" not in str(error.value)


def _damage_state(step):
    for path in (step / "state").rglob("*"):
        if path.is_file() and path.name != "commit_success.txt":
            path.write_bytes(b"garbage")


def _damage_arrays(step):
    for path in (step / "state").rglob("d/*"):
        path.write_bytes(b"garbage")


def _state_replaced_by_a_file(step):
    for path in sorted((step / "state").rglob("*"), reverse=True):
        path.unlink() if path.is_file() else path.rmdir()
    (step / "state").rmdir()
    (step / "state").write_bytes(b"garbage")


def _damage_metadata(step):
    (step / "metadata" / "metadata").write_bytes(b"{not json")


@pytest.mark.parametrize("damage", [_damage_state, _damage_arrays, _state_replaced_by_a_file, _damage_metadata])
def test_a_damaged_checkpoint_is_one_line_naming_it(tmp_path, damage):
    checkpointer = Checkpointer(tmp_path / "checkpoints")
    checkpointer.save(5, {"params": {"w": np.zeros((1, 2), np.float32)}}, {"identity": {"names": ["size=1/seed=0"]}})
    checkpointer.close()
    damage(tmp_path / "checkpoints" / "5")
    with pytest.raises(ValueError, match=f"^path: the checkpoint {tmp_path}/checkpoints/5 cannot be read, a file in it "
                                         r"is damaged or missing \(.+\); train the model again or restore the folder$"
                       ) as error:
        load_model(tmp_path)
    assert "\n" not in str(error.value) and len(str(error.value)) < 600


def test_a_checkpoint_without_a_model_is_named(tmp_path):
    checkpointer = Checkpointer(tmp_path / "checkpoints")
    checkpointer.save(5, {"w": np.zeros(2, np.float32)}, {"identity": {"names": ["size=1/seed=0"]}})
    checkpointer.close()
    with pytest.raises(ValueError, match=f"^path: the checkpoint {tmp_path}/checkpoints/5 holds no model: expected "
                                         r"parameters \('params'\)"):
        load_model(tmp_path)
