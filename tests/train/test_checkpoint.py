import jax.numpy as jnp
import numpy as np

from pushjax.train.checkpoint import Checkpointer


def _state(value):
    return {"step": jnp.asarray([value, value], jnp.int32), "params": {"w": jnp.full((2, 3), value, jnp.float32)}}


def test_restores_the_newest_checkpoint_and_keeps_max_to_keep(tmp_path):
    checkpointer = Checkpointer(tmp_path / "checkpoints", max_to_keep=2)
    assert checkpointer.latest_step() is None
    assert checkpointer.latest_metadata() is None
    assert checkpointer.restore_latest(_state(0)) is None
    for step in (10, 20, 30):
        checkpointer.save(step, _state(step), {"identity": {"names": ["a", "b"]}, "step": step})
    checkpointer.close()

    reopened = Checkpointer(tmp_path / "checkpoints")
    assert reopened.latest_step() == 30
    assert reopened.latest_metadata() == {"identity": {"names": ["a", "b"]}, "step": 30}
    step, state, metadata = reopened.restore_latest(_state(0))
    reopened.close()
    assert step == 30 and metadata["step"] == 30
    np.testing.assert_array_equal(state["params"]["w"], np.full((2, 3), 30, np.float32))
    assert state["step"].dtype == np.int32
    assert sorted(int(path.name) for path in (tmp_path / "checkpoints").iterdir() if path.name.isdigit()) == [20, 30]
