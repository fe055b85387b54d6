/* SPDX-License-Identifier: MIT */
/* The layout of every plain record that crosses libpoursim's C API into Python, as the compiler laid it out
 * (offsetof, sizeof): Python builds its ctypes classes from this table at load time (pour.records), so no
 * record is mirrored by hand and a reordered or retyped field cannot go unnoticed. */
#ifndef POURSIM_RECORD_LAYOUTS_H
#define POURSIM_RECORD_LAYOUTS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One field of one record. kind is the element's type: "i8" "u8" "i16" "u16" "i32" "u32" "i64" "u64" "f32"
 * "f64" "bool" "cstr" (a NUL-terminated const char *), a pointer "<kind>*", or the C name of a nested record
 * of this table. count is the array length (1 for a scalar); size is one element's. */
typedef struct {
  const char *record;  /* C type name, e.g. "poursim_obs_t" */
  size_t record_size;  /* sizeof the record */
  size_t record_align; /* alignof the record */
  const char *field;   /* member name */
  size_t offset;       /* offsetof(record, field) */
  size_t size;         /* sizeof one element */
  const char *kind;
  size_t count;
} poursim_record_field_t;

/* Row i of the table (records in turn, each one's fields in declaration order), NULL past the last. */
const poursim_record_field_t *poursim_record_field(int i);

/* Row i through plain out-parameters (a binding needs no record to read the table of records): 0, or
 * POURSIM_EINVAL past the last row (nothing written). Any out-pointer may be NULL. */
int poursim_record_field_info(int i, const char **record, size_t *record_size, size_t *record_align,
                              const char **field, size_t *offset, size_t *size, const char **kind, size_t *count);

#ifdef __cplusplus
}
#endif

#endif /* POURSIM_RECORD_LAYOUTS_H */
