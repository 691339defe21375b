"""pushjax: predicting the effect of pushes from depth images with learned perception and the
differentiable Lynch quasi-static pushing model."""

__version__ = "0.1.0"
