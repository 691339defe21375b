"""An experiment's outputs: the record rounded to 7 digits, and the code that wrote it named in it."""

import json

import matplotlib.pyplot as plt

from pushjax import outputs, provenance


def _recorded_provenance_matches_the_checkout(workdir):
    recorded = json.loads((workdir / "results.json").read_text())["provenance"]
    state = provenance.source_state()
    if state is None:  # pushjax installed, not a checkout: nothing to name
        assert recorded == {}
        return
    assert recorded["commit"].removesuffix("+changes") == state["commit"]
    assert recorded["commit"].endswith("+changes") is not state["clean"]
    if not state["clean"]:
        assert (workdir / recorded["source_diff"]).read_text() == state["diff"]


def test_a_report_is_compact_and_names_its_code(tmp_path):
    results = {"error_mm": 1.234567891234, "rows": [{"share": 0.1 + 0.2}], "name": "x"}
    paths = outputs.write_report(tmp_path, results, "| a |\n")
    written = json.loads(paths[0].read_text())
    assert written["error_mm"] == 1.234568 and written["rows"] == [{"share": 0.3}] and written["name"] == "x"
    assert paths[1].read_text() == "| a |\n" and "provenance" not in results  # the caller's dict is left alone
    _recorded_provenance_matches_the_checkout(tmp_path)


def test_results_with_a_figure_name_their_code(tmp_path):
    def draw(results, path):
        figure = plt.figure()
        figure.savefig(path)
        plt.close(figure)

    paths = outputs.write_results(tmp_path, {"value": 2}, "table\n", "figure.png", draw)
    assert json.loads(paths[0].read_text())["value"] == 2 and paths[2].stat().st_size > 0
    _recorded_provenance_matches_the_checkout(tmp_path)
