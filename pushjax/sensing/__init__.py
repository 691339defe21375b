"""Sensors made of trained models, for the filters (and, later, the controller): ``perception``, a trained model's
perception locating the pushed object in the testbed scene's rendered depth image. Not imported here: it needs
MuJoCo's renderer and a trained model."""
