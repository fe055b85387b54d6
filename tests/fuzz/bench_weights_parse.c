/* SPDX-License-Identifier: MIT */
/* Parse time of host_sim's weights.h loader against the file size, for the worst inputs of the 1 MiB the
 * loader reads: an accepted header made long by one comment, a header made long by many short
 * comment lines, and a file that is one single token. Prints the best of 5 runs per size; a linear
 * parser keeps ns/byte flat as the size doubles. Run by `scripts/bench.sh weights`; never judged. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "poursim/weights_file.h"

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static char *read_file(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (f == NULL) return NULL;
  char *buf = malloc(1 << 16);
  *len = fread(buf, 1, (1 << 16) - 1, f);
  fclose(f);
  return buf;
}

/* kind 0: the example with one comment after its first #define; 1: many "/ * ... * /" lines before it;
 * 2: one token of digits. */
static size_t make(int kind, const char *good, size_t good_len, size_t size, char *out) {
  if (kind == 2) {
    memset(out, '9', size);
    return size;
  }
  const char *at = strstr(good, "#define POUR_WEIGHTS_FORMAT 1") + strlen("#define POUR_WEIGHTS_FORMAT 1");
  size_t head = (size_t)(at - good), pad = size - good_len, n = 0;
  memcpy(out, good, head);
  n = head;
  if (kind == 0) {
    memcpy(out + n, " /*", 3);
    memset(out + n + 3, 'x', pad - 6);
    memcpy(out + n + pad - 3, " */", 3);
    n += pad;
  } else {
    for (size_t k = 0; k + 16 <= pad; k += 16) memcpy(out + n + k, "\n/* 012345678 */", 16);
    n += pad - pad % 16;
  }
  memcpy(out + n, at, good_len - head);
  return n + good_len - head;
}

int main(int argc, char **argv) {
  if (argc == 2 && strcmp(argv[1], "--help") == 0) {
    printf("usage: bench_weights_parse [EXAMPLE.h]\n  times host_sim's weights.h parser on 128 KiB .. 1 MiB "
           "headers grown from EXAMPLE.h\n  (default policy/example_weights.h): two accepted, one refused\n");
    return 0;
  }
  if (argc == 2 && strcmp(argv[1], "--version") == 0) {
    printf("bench_weights_parse %s\n", POUR_VERSION);
    return 0;
  }
  const char *example = argc > 1 ? argv[1] : "policy/example_weights.h";
  size_t good_len = 0;
  char *good = read_file(example, &good_len);
  if (good == NULL) {
    fprintf(stderr, "bench_weights_parse: cannot read %s\n", example);
    return 1;
  }
  good[good_len] = '\0';
  static poursim_weights_file_t wf;
  char err[POURSIM_ERR_LEN];
  char *buf = malloc(1 << 20);
  const char *names[] = {"accepted, one long comment", "accepted, 16-byte comment lines", "one token (refused)"};
  for (int kind = 0; kind < 3; ++kind) {
    printf("%s:\n", names[kind]);
    for (size_t size = 1 << 17; size <= 1 << 20; size <<= 1) {
      size_t len = make(kind, good, good_len, size, buf);
      double best = 1e9;
      int rc = 0;
      for (int run = 0; run < 5; ++run) {
        double t0 = now_s();
        rc = poursim_weights_parse(buf, len, "bench.h", &wf, err, sizeof err);
        double dt = now_s() - t0;
        if (dt < best) best = dt;
      }
      printf("  %7zu bytes: %7.2f ms  %5.2f ns/byte  (%s)\n", len, 1e3 * best, 1e9 * best / (double)len,
             rc == POURSIM_OK ? "accepted" : "refused");
    }
  }
  free(buf);
  free(good);
  return 0;
}
