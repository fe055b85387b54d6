/* SPDX-License-Identifier: MIT */
/* The signature of every libpoursim function a binding calls, as the compiler sees its declaration: Python
 * declares each function's argument and return types from this table at load time (pour.functions), so no
 * signature is restated by hand and a parameter added, removed or retyped in a header cannot go unnoticed. */
#ifndef POURSIM_FUNCTION_TABLE_H
#define POURSIM_FUNCTION_TABLE_H

#ifdef __cplusplus
extern "C" {
#endif

/* Row i: the function's name, its return kind and its parameters' kinds, comma-separated in order ("" for
 * none). A kind is the record table's ("i32", "f64", "cstr", a record's C name, ...; record_layouts.h), "void",
 * "<kind>*" a pointer to one, or "ptr" a pointer to anything else (an opaque handle, an untyped buffer).
 * Returns 0, or POURSIM_EINVAL past the last row (nothing written). Any out-pointer may be NULL. */
int poursim_function_info(int i, const char **name, const char **returns, const char **params);

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_FUNCTION_TABLE_H */
