"""Every Python block of README.md runs as written from the repository root and gives what the text says.

Each block runs in its own interpreter (a reader copies one block at a time), from the repository root, on the
committed artefacts only (no work directory): a block that needs a file nothing in the repository holds fails here.
A block may be followed by checks of what the text around it states (``STATED``).
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[1]
_BLOCK = re.compile(r"```python\n(.*?)```", re.DOTALL)

STATED = {
    "lynch.predict(contact, normal, action, l, mu)": """
import numpy as np
np.testing.assert_allclose(twist, [9.4e-05, 4.6e-03, 4.2e-02], rtol=0.05)
np.testing.assert_allclose(rotation_grad, (-0.881, 0.0), atol=1e-3)
assert action_jacobian.shape == (3, 2) and twists.shape == (5, 3)
""",
    "rollout.rollout(shape, jnp.zeros(3), path": """
import numpy as np
assert d_yaw[0] == 0 and np.all(np.isfinite(d_yaw[1])) and many.poses.shape == (2, 101, 3)
np.testing.assert_allclose(final[2], 0.37, atol=0.01)
np.testing.assert_allclose(np.linalg.norm(final[:2]), 0.043, atol=0.001)
""",
    "for _ in range(100):": """
assert position_error < 0.002 and abs(yaw_error) < 0.02, (position_error, yaw_error)
""",
    "model_file.read(": """
assert tuple(found.effects) == ("table_tilt", "limit_surface"), found.effects
""",
    "load_model(": """
import numpy as np
assert prediction.motion.shape == (3,) and np.all(np.isfinite(prediction.motion))
""",
    "mit.iter_pushes(": """
assert pushes.summary() is not None
""",
}
"""Snippet identifying a block -> checks run after it, of what the README says the block gives."""


def readme_blocks() -> list[str]:
    return _BLOCK.findall((REPOSITORY / "README.md").read_text())


def _checks(block: str) -> str:
    return "".join(check for key, check in STATED.items() if key in block)


def test_every_block_has_its_stated_checks():
    blocks = readme_blocks()
    assert len(blocks) >= 6
    assert all(sum(key in block for block in blocks) == 1 for key in STATED), "each STATED key names one block"


@pytest.mark.parametrize("index", range(len(readme_blocks())))
def test_readme_block_runs_as_written(index):
    block = readme_blocks()[index]
    environment = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    result = subprocess.run([sys.executable, "-c", block + _checks(block)], cwd=REPOSITORY, env=environment,
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, f"README block {index}:\n{block}\n{result.stderr[-3000:]}"
