"""fitting: not built yet (see the issues)."""
