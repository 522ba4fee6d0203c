"""The one exception users see: a message that names the offending key and the fix."""


class StabmapError(ValueError):
    """Bad input (scene, grid, query, file); the CLI prints the message and exits with status 2."""
