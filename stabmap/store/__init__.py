"""Storing atlases: the output variables' type, the Dataset, files and the checkpoint of --resume."""
