# SPDX-License-Identifier: MIT
"""The training methods: each algo.kind and the function that trains a run with it.

Every method's train(cfg, run_dir, resume, quiet, stop_after, make_runner) keeps its run in rundir.py's
directory; trainer.train looks the config's kind up here, and config.py refuses a kind that is not here,
naming those that are.
"""
from __future__ import annotations

from typing import Callable

from pour.train import ars, pg, rundir
from pour.train.settings import ConfigError

METHODS: dict[str, Callable[..., rundir.RunResult]] = {
    "vanilla": pg.train,   # the seed paper's eq. 19 (config.py pins its options)
    "pg": pg.train,        # the improved policy gradient
    "ars": ars.train,      # augmented random search
    "cem": ars.train,      # the cross-entropy method
}


def unknown(kind: str) -> str:
    """The error of a kind that names no method."""
    return f"algo.kind = {kind!r}: expected one of the training methods {', '.join(map(repr, METHODS))}"


def method(kind: str) -> Callable[..., rundir.RunResult]:
    """The train function of kind; ConfigError naming the methods if there is none."""
    if kind not in METHODS:
        raise ConfigError(unknown(kind))
    return METHODS[kind]
