"""Reading saved atlases: info, query, tables and plots (docs/query.md, docs/plots.md)."""
