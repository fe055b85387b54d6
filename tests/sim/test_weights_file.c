/* SPDX-License-Identifier: MIT */
/* host_sim's run-time weights.h loader: accepts the shipped headers, refuses each kind of bad one with
 * a message naming the field. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "poursim/weights_file.h"
#include "read_text.h"
#include "unity.h"

static poursim_weights_file_t wf;
static char err[POURSIM_ERR_LEN];
static char good[16384];
static size_t good_len;


void setUp(void) {
  err[0] = '\0';
  good_len = read_text(POUR_SOURCE_DIR "/policy/example_weights.h", good, sizeof good);
}

void tearDown(void) {}

/* good with the first occurrence of from replaced by to, then parsed; returns the status. */
static int parse_edited(const char *from, const char *to) {
  static char text[20000];
  const char *at = strstr(good, from);
  TEST_ASSERT_NOT_NULL_MESSAGE(at, from);
  size_t head = (size_t)(at - good);
  snprintf(text, sizeof text, "%.*s%s%s", (int)head, good, to, at + strlen(from));
  return poursim_weights_parse(text, strlen(text), "edited.h", &wf, err, sizeof err);
}

/* good with macro name's value replaced by value, then parsed; returns the status. */
static int parse_with_macro(const char *name, const char *value) {
  static char text[20000];
  char key[96];
  snprintf(key, sizeof key, "#define %s ", name);
  const char *at = strstr(good, key);
  TEST_ASSERT_NOT_NULL_MESSAGE(at, key);
  const char *rest = at + strlen(key);
  while (*rest && *rest != ' ' && *rest != '\n') ++rest; /* skip the old value */
  snprintf(text, sizeof text, "%.*s%s%s", (int)(at + strlen(key) - good), good, value, rest);
  return poursim_weights_parse(text, strlen(text), "edited.h", &wf, err, sizeof err);
}

/* The first value of the 2-D array called name in good. */
static const char *first_value(const char *name) {
  const char *p = strstr(good, name);
  TEST_ASSERT_NOT_NULL_MESSAGE(p, name);
  p = strchr(strchr(strchr(p, '=') + 1, '{') + 1, '{') + 1;
  while (*p == ' ' || *p == '\n') ++p;
  return p;
}

static void expect_error_naming(int rc, const char *field) {
  TEST_ASSERT_TRUE_MESSAGE(rc < 0, "a bad header was accepted");
  TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, field), err);
}

static void test_weights_file_AcceptsShippedHeadersAndMatchesCoreHash(void) {
  const char *paths[] = {POUR_SOURCE_DIR "/policy/example_weights.h", POUR_SOURCE_DIR "/policy/weights.h",
                         POUR_SOURCE_DIR "/tests/golden/example_weights_2.h"};
  for (size_t i = 0; i < sizeof paths / sizeof paths[0]; ++i) {
    TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_weights_load(paths[i], &wf, err, sizeof err), err);
    pour_policy_weights_t view;
    poursim_weights_view(&wf, &view);
    TEST_ASSERT_EQUAL_UINT32(wf.content_hash, pour_policy_weights_hash(&view));
    TEST_ASSERT_EQUAL_INT(POUR_OK, pour_policy_weights_validate(&view));
  }
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_weights_load(POUR_SOURCE_DIR "/policy/example_weights.h", &wf, err, sizeof err));
  TEST_ASSERT_EQUAL_INT(11, wf.n_actions);
  TEST_ASSERT_EQUAL_INT(-32768, wf.levels[0]);
  TEST_ASSERT_EQUAL_INT(32767, wf.levels[10]);
  TEST_ASSERT_EQUAL_INT(1, wf.has_float_reference);
  /* The float policy for rollouts: W / 2^f, levels / 32768. */
  double w[POURSIM_N_FEATURES * 16], lv[16];
  poursim_policy_t p;
  poursim_weights_float_policy(&wf, w, lv, &p);
  TEST_ASSERT_EQUAL_DOUBLE(ldexp(wf.w[0], -wf.w_frac_bits), w[0]);
  TEST_ASSERT_EQUAL_DOUBLE(-1.0, lv[0]);
  TEST_ASSERT_EQUAL_INT(wf.decision_period_ms, p.decision_period);
}

static void test_weights_file_RefusesWrongActionCount(void) {
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_weights_parse(good, good_len, "good.h", &wf, err, sizeof err));
  char fewer[16];
  snprintf(fewer, sizeof fewer, "%d", wf.n_actions - 1);
  expect_error_naming(parse_with_macro("POUR_WEIGHTS_N_ACTIONS", fewer), "pour_weights_w");
  expect_error_naming(parse_with_macro("POUR_WEIGHTS_N_ACTIONS", "17"), "POUR_WEIGHTS_N_ACTIONS");
}

static void test_weights_file_RefusesBadQFormat(void) {
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_weights_parse(good, good_len, "good.h", &wf, err, sizeof err));
  char other[16];
  snprintf(other, sizeof other, "%d", (wf.w_frac_bits + 1) % 16);
  expect_error_naming(parse_with_macro("POUR_WEIGHTS_W_FRAC_BITS", "16"), "POUR_WEIGHTS_W_FRAC_BITS");
  expect_error_naming(parse_with_macro("POUR_WEIGHTS_W_FRAC_BITS", "eleven"), "POUR_WEIGHTS_W_FRAC_BITS");
  /* Another f changes the hash: an edited Q format without re-export is caught. */
  expect_error_naming(parse_with_macro("POUR_WEIGHTS_W_FRAC_BITS", other), "POUR_WEIGHTS_CONTENT_HASH");
}

static void test_weights_file_RefusesTruncatedFile(void) {
  const char *levels = strstr(good, "pour_weights_action_levels_q15[");
  TEST_ASSERT_NOT_NULL(levels);
  size_t cut = (size_t)(levels - good) + 80; /* in the middle of the levels */
  expect_error_naming(poursim_weights_parse(good, cut, "cut.h", &wf, err, sizeof err), "pour_weights_action_levels_q15");
  const char *w = strstr(good, "pour_weights_w[");
  cut = (size_t)(w - good) + 150; /* in the middle of W */
  expect_error_naming(poursim_weights_parse(good, cut, "cut.h", &wf, err, sizeof err), "pour_weights_w");
  const char *hash = strstr(good, "#define POUR_WEIGHTS_CONTENT_HASH");
  expect_error_naming(poursim_weights_parse(good, (size_t)(hash - good), "cut.h", &wf, err, sizeof err),
                      "truncated");
}

/* Every case of tests/data/weights_cases/cases.tsv (shared with tests/python/test_weights_h.py): accepted
 * or refused as listed, the message containing the listed text and naming the file. */
static void test_weights_file_AgreesWithTheSharedCaseTable(void) {
  const char *dir = POUR_SOURCE_DIR "/tests/data/weights_cases";
  char path[512], line[512];
  snprintf(path, sizeof path, "%s/cases.tsv", dir);
  FILE *f = fopen(path, "r");
  TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
  int n = 0;
  while (fgets(line, sizeof line, f) != NULL) {
    if (line[0] == '#') continue;
    line[strcspn(line, "\n")] = '\0';
    char *file = strtok(line, "\t"), *verdict = strtok(NULL, "\t");
    char *message = verdict != NULL && strcmp(verdict, "refuse") == 0 ? strtok(NULL, "\t") : NULL;
    TEST_ASSERT_NOT_NULL_MESSAGE(verdict, file);
    snprintf(path, sizeof path, "%s/%s", dir, file);
    err[0] = '\0';
    int rc = poursim_weights_load(path, &wf, err, sizeof err);
    printf("%-34s %s -> %s\n", file, verdict, rc == POURSIM_OK ? "accepted" : err);
    if (message == NULL) {
      TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, rc, err);
    } else {
      expect_error_naming(rc, message);
      TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, file), err);
    }
    ++n;
  }
  fclose(f);
  TEST_ASSERT_GREATER_THAN_INT(40, n);
}

/* The largest file the loader reads is refused beyond 1 MiB, before parsing. */
static void test_weights_file_RefusesFilesOverOneMebibyte(void) {
  const char *path = "big_weights.h";
  FILE *f = fopen(path, "wb");
  TEST_ASSERT_NOT_NULL(f);
  fputs(good, f);
  while (ftell(f) <= (1L << 20)) fputs("/* padding */\n", f);
  fclose(f);
  expect_error_naming(poursim_weights_load(path, &wf, err, sizeof err), "larger than 1048576 bytes");
  remove(path);
}

static void test_weights_file_RefusesNaNInFloatReference(void) {
  const char *first = first_value("pour_weights_w_float[");
  const char *comma = strchr(first, ',');
  static char text[20000];
  snprintf(text, sizeof text, "%.*sNAN%s", (int)(first - good), good, comma);
  expect_error_naming(poursim_weights_parse(text, strlen(text), "nan.h", &wf, err, sizeof err), "pour_weights_w_float[0][0]");
  snprintf(text, sizeof text, "%.*s1e999f%s", (int)(first - good), good, comma);
  expect_error_naming(poursim_weights_parse(text, strlen(text), "inf.h", &wf, err, sizeof err), "pour_weights_w_float[0][0]");
}

static void test_weights_file_RefusesEditedWeightsAndBadValues(void) {
  /* One weight edited by hand: the content hash no longer matches. */
  const char *first = first_value("pour_weights_w[");
  const char *comma = strchr(first, ',');
  static char text[20000];
  snprintf(text, sizeof text, "%.*s123%s", (int)(first - good), good, comma);
  expect_error_naming(poursim_weights_parse(text, strlen(text), "edited.h", &wf, err, sizeof err), "POUR_WEIGHTS_CONTENT_HASH");
  snprintf(text, sizeof text, "%.*s40000%s", (int)(first - good), good, comma);
  expect_error_naming(poursim_weights_parse(text, strlen(text), "big.h", &wf, err, sizeof err), "pour_weights_w[0][0]");
  {
    /* The second level made equal to the first. */
    const char *lv = strchr(strchr(strstr(good, "pour_weights_action_levels_q15["), '=') + 1, '{') + 1;
    const char *c1 = strchr(lv, ','), *c2 = strchr(c1 + 1, ',');
    snprintf(text, sizeof text, "%.*s, %.*s%s", (int)(c1 - good), good, (int)(c1 - lv), lv, c2);
    expect_error_naming(poursim_weights_parse(text, strlen(text), "levels.h", &wf, err, sizeof err),
                        "strictly increasing");
  }
  expect_error_naming(parse_edited("#define POUR_WEIGHTS_TAU_MAX_MNM", "#define POUR_WEIGHTS_TAU_MAX_MNM 5\n#define POUR_WEIGHTS_TAU_MAX_MNM"),
                      "defined twice");
  TEST_ASSERT_EQUAL_INT(POURSIM_EIO, poursim_weights_load("/nonexistent/weights.h", &wf, err, sizeof err));
  TEST_ASSERT_NOT_NULL(strstr(err, "/nonexistent/weights.h"));
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_weights_file_AcceptsShippedHeadersAndMatchesCoreHash);
  RUN_TEST(test_weights_file_RefusesWrongActionCount);
  RUN_TEST(test_weights_file_RefusesBadQFormat);
  RUN_TEST(test_weights_file_RefusesTruncatedFile);
  RUN_TEST(test_weights_file_RefusesNaNInFloatReference);
  RUN_TEST(test_weights_file_RefusesEditedWeightsAndBadValues);
  RUN_TEST(test_weights_file_AgreesWithTheSharedCaseTable);
  RUN_TEST(test_weights_file_RefusesFilesOverOneMebibyte);
  return UNITY_END();
}
