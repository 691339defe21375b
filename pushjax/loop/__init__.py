"""Closing the loop on measured pushes: find the effect behind the Lynch model's residual, fit it, report.

Modules: :mod:`~pushjax.loop.windows` (prediction windows and split), :mod:`~pushjax.loop.metrics` (errors),
:mod:`~pushjax.loop.diagnose` (residual versus variables), :mod:`~pushjax.loop.fit` (effect parameters),
:mod:`~pushjax.loop.select` (ranking and forward selection), :mod:`~pushjax.loop.correction` (learned
fallback), :mod:`~pushjax.loop.report` and :mod:`~pushjax.loop.pipeline` (the whole loop).
"""

from pushjax.loop.pipeline import LoopConfig, close_loop

__all__ = ["LoopConfig", "close_loop"]
