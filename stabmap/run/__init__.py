"""Running atlases: tasks, threads or a dask cluster, adaptive cells, refinement and critical values (docs/systems.md)."""
