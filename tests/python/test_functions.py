# SPDX-License-Identifier: MIT
"""libpoursim's functions are declared from the library's own function table (pour.functions): every
function tools/ calls is in it, each declared as its header says, and no argtypes is written by hand in tools/
but the two that read the tables themselves."""
from __future__ import annotations

import ast
import ctypes as C
import re
from pathlib import Path

import pytest

from pour import functions, records
from pour.libpoursim import SimError

TOOLS = Path(__file__).resolve().parents[2] / "tools"


@pytest.fixture(autouse=True)
def _lib(build_dir, monkeypatch):
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))


def test_each_function_is_declared_as_its_header_says():
    """Signatures read off host_sim/include/poursim/{poursim,core,stepper}.h and firmware/include/pour/params.h."""
    lib, R, P = functions.library(), records.record, C.POINTER
    # int poursim_step(poursim_world_t *world, double action, poursim_obs_t *out);
    assert lib.poursim_step.argtypes == [C.c_void_p, C.c_double, P(R("poursim_obs_t"))]
    assert lib.poursim_step.restype is C.c_int32
    # poursim_reward_t poursim_default_reward(void);
    assert lib.poursim_default_reward.argtypes == [] and lib.poursim_default_reward.restype is R("poursim_reward_t")
    # int16_t poursim_envelope_apply(poursim_envelope_t *env, int16_t requested, int32_t theta_urad,
    #                                int32_t omega_urad_s);
    assert lib.poursim_envelope_apply.argtypes == [C.c_void_p, C.c_int16, C.c_int32, C.c_int32]
    # int poursim_stepper_advance(poursim_stepper_t *s, int action, double level, int ticks, double *reward,
    #                             int16_t *torque, char *err, size_t err_len);
    assert lib.poursim_stepper_advance.argtypes == [C.c_void_p, C.c_int32, C.c_double, C.c_int32, P(C.c_double),
                                                    P(C.c_int16), C.c_char_p, C.c_size_t]
    # int poursim_config_key_info(const char *key, int *integer, double *min, double *max, double *def,
    #                             const char **unit, const char **doc);
    assert lib.poursim_config_key_info.argtypes == [C.c_char_p, P(C.c_int32)] + [P(C.c_double)] * 3 + \
        [P(C.c_char_p)] * 2
    # const pour_param_info_t *pour_param_info(uint8_t id);  void poursim_core_decide(poursim_core_t *core);
    assert lib.pour_param_info.restype == P(R("pour_param_info_t"))
    assert lib.poursim_core_decide.restype is None and lib.poursim_core_decide.argtypes == [C.c_void_p]
    assert lib.poursim_version().decode()


def test_every_function_tools_calls_is_in_the_table():
    table = {r.name for r in functions.library_table()}
    called = set()
    for path in sorted(TOOLS.rglob("*.py")):
        called |= set(re.findall(r"\.((?:poursim|pour)_[a-z0-9_]+)\(", path.read_text(encoding="utf-8")))
    assert len(called) > 50 and called <= table, sorted(called - table)


def test_a_function_not_in_the_table_cannot_be_called():
    with pytest.raises(SimError, match="function table has no 'poursim_not_there'"):
        functions.library().poursim_not_there()
    assert hasattr(functions.library(), "poursim_step") and not hasattr(functions.library(), "poursim_not_there")


def test_a_kind_the_binding_does_not_know_is_refused():
    assert functions.ctype("poursim_obs_t*", records.records()) == C.POINTER(records.record("poursim_obs_t"))
    assert functions.ctype("cstr*", {}) == C.POINTER(C.c_char_p) and functions.ctype("void", {}) is None
    for bad in ("q7", "poursim_world_t", "void*", "ptr*"):
        with pytest.raises(SimError, match=f"names a kind {re.escape(repr(bad))}"):
            functions.ctype(bad, records.records())


def test_a_reordered_signature_is_declared_reordered():
    """The declaration follows the table's row, not a list kept in Python."""
    row = functions.Signature("poursim_envelope_apply", "i16", ("ptr", "i32", "i32", "i16"))
    lib = C.CDLL(functions.library().path)
    fns = functions.Functions(lib, [row], {})
    assert fns.poursim_envelope_apply.argtypes == [C.c_void_p, C.c_int32, C.c_int32, C.c_int16]
    assert fns.names == ["poursim_envelope_apply"]


def test_no_argtypes_is_written_by_hand_in_tools():
    """Only the readers of the two tables (poursim_record_field_info, poursim_function_info) declare one."""
    hand = []
    for path in sorted(TOOLS.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Attribute) and node.attr == "argtypes" and isinstance(node.ctx, ast.Store):
                hand.append(f"{path.relative_to(TOOLS)}")
    assert sorted(hand) == ["pour/functions.py", "pour/functions.py", "pour/records.py"], hand
