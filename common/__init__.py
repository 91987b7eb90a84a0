"""Small helpers below both models and the pipeline: rigid-body kinematics, plate inertia,
atomic file output and the declaration of settings. Pure numpy and the standard library; it
imports nothing from the project, so both the analytical model and the FEM reference may use
it without sharing model code (two models that check each other must not share physics
code: common/README.md)."""
