"""swtlab's command line: a thin layer that wires the pipeline stages together."""
