"""softflow: not built yet (see the issues)."""
