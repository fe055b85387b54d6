/* SPDX-License-Identifier: MIT */
/* The Linux controller's parameter storage: the blob of pour/params.h (version, CRC-32) in one file, written
 * to a temporary file beside it, synced and renamed over it, so a crash leaves the old file or the new. */
#ifndef POUR_LINUX_PARAMS_FILE_H
#define POUR_LINUX_PARAMS_FILE_H

#include "pour/params.h"

/* Reads path onto *params. Returns 0 if loaded, 1 if there is no such file (*params untouched), -1 with a
 * message naming the file and what is wrong on stderr (unreadable, truncated, bad magic or version, CRC
 * mismatch, a parameter unknown or out of range). */
int pour_params_file_load(const char *path, pour_params_t *params);

/* Writes the whole set to path atomically. Returns 0, or -1 with a message on stderr. */
int pour_params_file_save(const char *path, const pour_params_t *params);

#endif /* POUR_LINUX_PARAMS_FILE_H */
