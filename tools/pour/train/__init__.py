"""The trainer: its config, its training methods (a registry of them), their shared run directory and the
executors training and evaluation run episodes on."""
