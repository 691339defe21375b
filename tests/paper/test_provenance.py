"""A record's provenance: the commit of the code, and the diff of changed code kept beside the record."""

import subprocess

import numpy as np
import pytest

from pushjax import provenance


def _git(root, *arguments):
    return subprocess.run(["git", *arguments], cwd=root, check=True, capture_output=True, text=True).stdout


@pytest.fixture
def checkout(tmp_path):
    root = tmp_path / "checkout"
    (root / "pushjax").mkdir(parents=True)
    (root / "results").mkdir()
    (root / "pushjax" / "model.py").write_text("WIDTH = 64\n")
    (root / "results" / "record.json").write_text("{}\n")
    (root / "pyproject.toml").write_text("[project]\n")
    _git(root, "init", "-q")
    _git(root, "add", ".")
    _git(root, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "code")
    return root


def test_results_do_not_dirty_the_code_and_changed_code_is_kept(checkout, tmp_path):
    commit = _git(checkout, "rev-parse", "HEAD").strip()
    (checkout / "results" / "record.json").write_text('{"changed": true}\n')  # a run's own output
    state = provenance.source_state(checkout)
    assert state == {"commit": commit, "clean": True, "diff": ""}
    assert provenance.git_commit(checkout) == commit
    assert provenance.write_source_diff(tmp_path / "run", state) == {"commit": commit}
    assert not (tmp_path / "run").exists()

    (checkout / "pushjax" / "model.py").write_text("WIDTH = 128\n")
    (checkout / "pushjax" / "new_head.py").write_text("DEPTH = 3\n")  # untracked code counts too
    state = provenance.source_state(checkout)
    assert not state["clean"] and provenance.git_commit(checkout) == commit + "+changes"
    assert "-WIDTH = 64" in state["diff"] and "+WIDTH = 128" in state["diff"]
    assert "+++ b/pushjax/new_head.py (untracked)" in state["diff"] and "+DEPTH = 3" in state["diff"]
    recorded = provenance.write_source_diff(tmp_path / "run", state)
    assert recorded["commit"] == commit + "+changes"
    assert (tmp_path / "run" / recorded["source_diff"]).read_text() == state["diff"]
    assert provenance.write_source_diff(tmp_path / "run", state) == recorded  # the same diff: one file
    assert len(list((tmp_path / "run" / provenance.PROVENANCE_DIR).iterdir())) == 1
    # The diff applies to the commit and gives the code back.
    _git(checkout, "stash", "-q", "--include-untracked")
    tracked = (tmp_path / "run" / recorded["source_diff"]).read_text().split("--- /dev/null")[0]
    (tmp_path / "tracked.diff").write_text(tracked)
    _git(checkout, "apply", str(tmp_path / "tracked.diff"))
    assert (checkout / "pushjax" / "model.py").read_text() == "WIDTH = 128\n"


def test_no_checkout_no_provenance(tmp_path):
    assert provenance.source_state(tmp_path) is None and provenance.git_commit(tmp_path) is None
    assert provenance.write_source_diff(tmp_path, None) == {}


def test_file_digests_are_sha256sums_and_read_back(tmp_path):
    (tmp_path / "push_effects-train.array_record-00000-of-00002").write_bytes(b"abc")
    (tmp_path / "push_effects-test.array_record-00000-of-00001").write_bytes(b"")
    (tmp_path / "dataset_info.json").write_text("{}")  # not a data file
    digests = provenance.file_digests(tmp_path)
    assert list(digests) == ["push_effects-test.array_record-00000-of-00001",
                             "push_effects-train.array_record-00000-of-00002"]
    assert digests["push_effects-train.array_record-00000-of-00002"] == (
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad")  # sha256("abc")
    text = provenance.digests_text(digests)
    assert provenance.parse_digests(text) == digests
    check = subprocess.run(["sha256sum", "-c", "-"], input=text, cwd=tmp_path, capture_output=True, text=True)
    assert check.returncode == 0, check.stdout + check.stderr


def test_a_tree_digest_changes_with_any_bit_name_dtype_or_shape():
    tree = {"dense": {"kernel": np.arange(6, dtype=np.float32).reshape(2, 3), "bias": np.zeros(3, np.float32)}}
    digest = provenance.tree_digest(tree)
    assert digest == provenance.tree_digest({"dense": {"bias": np.zeros(3, np.float32),
                                                      "kernel": np.arange(6, dtype=np.float32).reshape(2, 3)}})
    flipped = tree["dense"]["kernel"].copy()
    flipped.view(np.uint32)[0, 0] ^= 1  # the last bit of one value
    changed = [
        {"dense": {**tree["dense"], "kernel": flipped}},
        {"dense": {**tree["dense"], "kernel": tree["dense"]["kernel"].reshape(3, 2)}},
        {"dense": {**tree["dense"], "bias": np.zeros(3, np.float64)}},
        {"other": tree["dense"]},
    ]
    assert len({digest, *(provenance.tree_digest(other) for other in changed)}) == 1 + len(changed)
