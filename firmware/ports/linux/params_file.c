/* SPDX-License-Identifier: MIT */
#include "params_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

int pour_params_file_load(const char *path, pour_params_t *params) {
  FILE *f = fopen(path, "rb");
  if (f == NULL) {
    if (errno == ENOENT) {
      return 1;
    }
    fprintf(stderr, "pour_controller: parameter file %s: cannot open (%s)\n", path, strerror(errno));
    return -1;
  }
  uint8_t buf[POUR_PARAMS_BLOB_MAX + 1u]; /* one byte more: a longer file is not ours */
  const size_t n = fread(buf, 1, sizeof buf, f);
  const int failed = ferror(f);
  fclose(f);
  if (failed) {
    fprintf(stderr, "pour_controller: parameter file %s: read error\n", path);
    return -1;
  }
  uint8_t bad_id = 0;
  const pour_params_blob_t st = pour_params_deserialize(buf, (uint32_t)n, params, &bad_id);
  if (st == POUR_PARAMS_BLOB_BAD_VALUE) {
    const pour_param_info_t *info = pour_param_info(bad_id);
    fprintf(stderr, "pour_controller: parameter file %s: parameter %u (%s) is unknown, out of range or "
            "inconsistent; fix the file (pour-bench config) or delete it to start from the defaults\n",
            path, (unsigned)bad_id, info != NULL ? info->name : "no such parameter");
    return -1;
  }
  if (st != POUR_PARAMS_BLOB_OK) {
    fprintf(stderr, "pour_controller: parameter file %s: %s (%zu bytes); delete it to start from the defaults\n",
            path, pour_params_blob_name(st), n);
    return -1;
  }
  return 0;
}

int pour_params_file_save(const char *path, const pour_params_t *params) {
  uint8_t buf[POUR_PARAMS_BLOB_MAX];
  const uint32_t n = pour_params_serialize(params, buf, sizeof buf);
  char tmp[4096];
  if (n == 0u || (size_t)snprintf(tmp, sizeof tmp, "%s.tmp", path) >= sizeof tmp) {
    fprintf(stderr, "pour_controller: parameter file %s: path too long\n", path);
    return -1;
  }
  const int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) {
    fprintf(stderr, "pour_controller: parameter file %s: cannot create (%s)\n", tmp, strerror(errno));
    return -1;
  }
  const int ok = write(fd, buf, n) == (ssize_t)n && fsync(fd) == 0;
  if (close(fd) != 0 || !ok || rename(tmp, path) != 0) {
    fprintf(stderr, "pour_controller: parameter file %s: cannot write (%s)\n", path, strerror(errno));
    (void)unlink(tmp);
    return -1;
  }
  return 0;
}
