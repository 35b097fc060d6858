"""gvsrom: GVS Cosserat-rod simulation of soft robots and their reduced-order models.

The same library the ``gvsrom`` command line calls, with NumPy arrays in and out::

    import gvsrom
    robot = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -5).build()
    eq = robot.statics()
    eq.tip_position          # numpy array, [m]
"""

from ._gvsrom import (
    ConvergenceError,
    Dataset,
    GvsromError,
    IntegrationError,
    Model,
    Reconstruction,
    Robot,
    Scenario,
    Statics,
    StaticsBatch,
    Stepper,
    __version__,
    compare,
    dataset,
    load_dataset,
    load_model,
    plot,
    pod,
    presets,
    reproduce,
    train,
)

__all__ = [
    "ConvergenceError",
    "Dataset",
    "GvsromError",
    "IntegrationError",
    "Model",
    "Reconstruction",
    "Robot",
    "Scenario",
    "Statics",
    "StaticsBatch",
    "Stepper",
    "__version__",
    "compare",
    "dataset",
    "load_dataset",
    "load_model",
    "plot",
    "pod",
    "presets",
    "reproduce",
    "train",
]
