"""The paper's own numbers, for the "paper" columns of our tables (Kloss, Schaal & Bohg, IJRR 2022).

They are read from a ``paper_tables.json`` (Tables 1-5, Sec. V, the text of Figs. 6, 7 and 9): the file named by
the environment variable ``PUSHJAX_PAPER_TABLES``, else ``../shared/data/paper_tables.json`` beside the
source checkout (`pushjax.provenance.source_checkout`; an installed pushjax needs the variable). Without it every lookup returns None and the tables have no paper column; nothing else changes.

Our training sizes map to the paper's by role: 2 500 is 2 500, and an experiment's largest size is the paper's
largest (Table 1: 190 000, Table 3: 114 000), whatever our scale makes it (``cpu``: 19 800 and 11 664).
"""

from __future__ import annotations

import functools
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from pushjax import provenance

ENVIRONMENT_VARIABLE = "PUSHJAX_PAPER_TABLES"

_SIZED_TABLES = {"data_efficiency": ("table1_data_efficiency", "190000"),
                 "data_efficiency_full": ("table1_data_efficiency", "190000"),
                 "new_pushes": ("table3_new_pushes", "114000")}
_TEXT = {"velocities": ("fig6_velocities", "text"), "objects": ("fig7_objects", "text"),
         "error_velocities": ("table4_error_variants_190k", "fig9_text")}


def path() -> Path | None:
    """The ``paper_tables.json`` in use, or None when there is none."""
    named = os.environ.get(ENVIRONMENT_VARIABLE)
    checkout = provenance.source_checkout()
    candidate = (Path(named) if named else
                 None if checkout is None else checkout.parent / "shared" / "data" / "paper_tables.json")
    return candidate if candidate is not None and candidate.is_file() else None


@functools.cache
def _load(file: Path | None) -> dict:
    if file is None:
        return {}
    try:
        return json.loads(file.read_text())
    except (OSError, ValueError) as error:
        raise ValueError(f"{ENVIRONMENT_VARIABLE}: {file} is not a readable JSON file ({error})") from None


def tables() -> dict:
    """The paper's tables ({} without a ``paper_tables.json``)."""
    return _load(path())


def _entry(experiment: str, model: str, size_role: str | None, l_scale: float) -> Mapping | None:
    """The paper's cell {metric: [value, se]} of `model` in `experiment`'s table, or None."""
    paper = tables()
    if experiment in _SIZED_TABLES:
        table, largest = _SIZED_TABLES[experiment]
        table = paper.get(table, {})
        if model in ("physics", "zero"):
            return table.get(model)
        entry = table.get({"small": "2500", "largest": largest}.get(size_role, ""), {}).get(model)
        if experiment in ("data_efficiency", "data_efficiency_full") and size_role == "largest":  # Table 2: the state errors at 190 k
            entry = {**(entry or {}), **paper.get("table2_state_errors_190k", {}).get(model, {})} or None
        return entry
    if experiment == "error_variants":
        if l_scale != 1.0:
            return paper.get("table5_wrong_l_190k", {}).get(f"{l_scale:g}", {}).get(model) if size_role in (
                "largest", None) else None
        return paper.get("table4_error_variants_190k", {}).get(model) if size_role in ("largest", None) else None
    if experiment == "viewpoint" and model == "hybrid":
        return paper.get("sec5_viewpoint_190k", {}).get("hybrid_free_view")
    return None


def size_role(size: int | None, sizes: Sequence[int]) -> str | None:
    """``"small"`` for 2 500, ``"largest"`` for the largest of `sizes`, ``""`` for another size, None for a baseline
    (no size)."""
    if size is None:
        return None
    if size == 2500:
        return "small"
    return "largest" if sizes and size == max(sizes) else ""


def cell(experiment: str, model: str, size_role_: str | None, metrics: Sequence[str], l_scale: float = 1.0
         ) -> str | None:
    """The paper's `metrics` of one cell joined by `` / `` (``–`` for a metric it does not give), or None.

    Args:
      experiment: our binary's name (``data_efficiency``, ``new_pushes``, ``error_variants``, ``viewpoint``).
      model: a variant or baseline.
      size_role_: `size_role` of the cell's training size.
      metrics: our metric names (``trans_percent``, ``rot_percent``, ``pos_mm``, ``contact_mm``, ``normal_deg``, ``s``,
        ``push_velocity_deg``).
      l_scale: the factor on ``l`` (Table 5).
    """
    entry = _entry(experiment, model, size_role_, l_scale)
    if not entry:
        return None
    values = []
    for metric in metrics:
        value = entry.get(_KEYS.get(metric, metric))
        values.append("–" if value is None else f"{(value[0] if isinstance(value, list) else value):g}")
    return None if all(value == "–" for value in values) else " / ".join(values)


_KEYS = {"trans_percent": "trans", "rot_percent": "rot", "pos_mm": "pos_mm", "contact_mm": "contact_mm",
         "normal_deg": "normal_deg", "s": "s", "push_velocity_deg": "v_p_deg"}


def notes(experiment: str) -> list[str]:
    """The paper's statements for a figure it gives no table of (Figs. 6, 7, 9), or []."""
    if experiment not in _TEXT:
        return []
    table, key = _TEXT[experiment]
    text = tables().get(table, {}).get(key, [])
    return [text] if isinstance(text, str) else list(text)
