# SPDX-License-Identifier: MIT
"""Registers pour's Gymnasium ids when a program imports gymnasium, so that gymnasium.make("pour/Pour-v0")
works without importing pour first. Gymnasium 1.x loads no plugins (its registry is a plain dict filled
by register() calls), so the installed package ships _pour_gymnasium.pth, which Python's site module runs
at start-up: it only puts a finder at the front of sys.meta_path. Neither gymnasium nor pour is imported
then; when gymnasium is, the finder lets its own loader run it and then calls
pour.sim.gym_ids.register_all() (lazy ids: pour.sim.gym_env is imported only by gymnasium.make)."""
import sys


class _GymnasiumFinder:
    """A meta-path finder that answers only for 'gymnasium', once, with gymnasium's own spec."""

    @classmethod
    def find_spec(cls, name, path=None, target=None):
        if name != "gymnasium":
            return None
        sys.meta_path.remove(cls)
        from importlib.util import find_spec

        spec = find_spec(name)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        run_gymnasium = spec.loader.exec_module

        def exec_module(module):
            run_gymnasium(module)
            _register()

        spec.loader.exec_module = exec_module
        return spec


def _register() -> None:
    try:
        from pour.sim import gym_ids
    except ImportError as e:
        import warnings

        warnings.warn(f"pour's Gymnasium ids (pour/Pour-v0, ...) are not registered: {e}", stacklevel=2)
        return
    gym_ids.register_all()


def install() -> None:
    """Called from _pour_gymnasium.pth: arms the finder unless gymnasium is already imported or armed."""
    if "gymnasium" in sys.modules:
        _register()
    elif _GymnasiumFinder not in sys.meta_path:
        sys.meta_path.insert(0, _GymnasiumFinder)
