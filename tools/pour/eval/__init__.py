"""Evaluation of policies and training runs: held-out tables, robustness, sweeps and figures."""
