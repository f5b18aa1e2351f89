"""Sim-to-real gap diagnosis (docs/gap-report.md): where the simulation misses the measured
wheel, which unmodelled effect explains it, how far the gap shrinks once it is added.

Modules: ``measured`` (measured points: database, WPM CSV, CMU smooth_runs.csv),
``simulated`` (model TOML or a simulator's WPM CSV with model corrections), ``candidates``,
``fit``, ``crossval``, ``decide``, ``laws`` (the verdict under each law of each effect),
``next_test`` (the next test by expected information gain), ``shrink``, ``regions``, ``report``,
``diagnose`` (the pure pipeline), ``api`` (files in, report out), ``calibrate`` (base-model
soil fit), ``bench`` (the blind gap-bench).
"""
