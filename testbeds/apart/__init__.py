"""A gap-bench generator written apart from the project's physics (docs/validation/gap-apart.md).

Its own steady-state wheel-soil solver (Reece's dimensionless pressure-sinkage, Wong's shear
law with a hump, Iagnemma's linearised stress distribution), each effect drawn from a
randomised family of shapes per campaign, effects outside the diagnosis' six, per-run soil
scatter, replicates; raw runs written through ``validation.second_rig``'s signal and sensor
layer. An import contract (pyproject.toml) keeps it from ``terramechanics``, ``sim_gap``,
``virtual_testbed`` and every estimator.

    python -m testbeds.apart.campaigns --seed 1 --n 8 --out /tmp/apart
    python -m testbeds.apart.score /tmp/apart --jobs 2
    python -m testbeds.apart.followup /tmp/apart --out /tmp/followup
    python -m testbeds.apart.misfit /tmp/apart
    python -m testbeds.apart.compare before.json after.json
"""
