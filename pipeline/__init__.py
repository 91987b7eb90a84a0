"""Validation pipeline: scene loading, orchestration of both models, mode pairing, error
tables, baselines and the command line."""
