"""The exceptions of magsim; their messages are magsim-scene's one-line errors."""


class SceneError(ValueError):
    """A bad scene: the message names the file (or origin) and the JSON path."""


class SimulationError(RuntimeError):
    """A step failed (a non-finite value, a blow-up); the simulation is at its last good state.

    step: the failing step (1-based; -1 when unknown), body: the body's index (-1: none),
    body_name, quantity: what went non-finite ("velocity", "M", ...).
    """

    def __init__(self, message, step=-1, body=-1, body_name="", quantity=""):
        super().__init__(message)
        self.step = step
        self.body = body
        self.body_name = body_name
        self.quantity = quantity
