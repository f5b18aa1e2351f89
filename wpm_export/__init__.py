"""wpm_export: not built yet (see the issues)."""
