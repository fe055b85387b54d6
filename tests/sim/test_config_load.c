/* SPDX-License-Identifier: MIT */
/* poursim_config_load: the same limits as the weights.h loader (bounded size, text only, each key once)
 * and every error naming the file and the line. */
#include <stdio.h>
#include <string.h>

#include "poursim/poursim.h"
#include "read_text.h"
#include "unity.h"

static poursim_config_t cfg;
static char err[POURSIM_ERR_LEN];

void setUp(void) {
  cfg = poursim_default_config();
  err[0] = '\0';
}

void tearDown(void) {}

/* Writes len bytes of text to a file in the working directory and loads it. */
static int load_text(const char *name, const char *text, size_t len) {
  FILE *f = fopen(name, "wb");
  TEST_ASSERT_NOT_NULL(f);
  TEST_ASSERT_EQUAL_size_t(len, fwrite(text, 1, len, f));
  fclose(f);
  return poursim_config_load(name, &cfg, err, sizeof err);
}

static void expect_error(int rc, const char *where, const char *what) {
  TEST_ASSERT_TRUE_MESSAGE(rc < 0, "a bad config was accepted");
  TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, where), err);
  TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, what), err);
}

static void test_config_load_ReadsTheShippedConfig(void) {
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_config_load(POUR_SOURCE_DIR "/configs/sim/default.cfg", &cfg, err, sizeof err), err);
  static const char crlf[] = "# comment\r\nseed = 7\r\n\r\nfriction = 0.1 # why\r\n";
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, load_text("crlf.cfg", crlf, sizeof crlf - 1), err);
  TEST_ASSERT_EQUAL_UINT32(7, cfg.seed);
  TEST_ASSERT_EQUAL_DOUBLE(0.1, cfg.friction);
}


/* configs/sim/default.cfg is what write_default_cfg writes (the target default_cfg regenerates it): every
 * key of config_fields.h once, at its default. */
static void test_config_load_ShippedConfigIsTheGeneratedDefaults(void) {
  static char shipped[32768], written[32768];
  const size_t n = read_text(POUR_SOURCE_DIR "/configs/sim/default.cfg", shipped, sizeof shipped);
  const poursim_config_t defaults = poursim_default_config();
  TEST_ASSERT_EQUAL_INT_MESSAGE(POURSIM_OK, poursim_config_write(&defaults, "defaults.cfg", err, sizeof err), err);
  const size_t m = read_text("defaults.cfg", written, sizeof written);
  TEST_ASSERT_EQUAL_size_t_MESSAGE(m, n, "configs/sim/default.cfg is stale: cmake --build --preset host --target default_cfg");
  TEST_ASSERT_EQUAL_STRING_MESSAGE(written, shipped, "configs/sim/default.cfg is stale: cmake --build --preset host --target default_cfg");
  int keys = 0;
  for (const char *key; (key = poursim_config_key(keys)) != NULL; ++keys) {
    char line[64];
    snprintf(line, sizeof line, "\n%s = ", key);
    const char *at = strstr(shipped, line);
    TEST_ASSERT_NOT_NULL_MESSAGE(at, key);
    TEST_ASSERT_NULL_MESSAGE(strstr(at + 1, line), key);
  }
  TEST_ASSERT_TRUE(keys > 40);
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_load("defaults.cfg", &cfg, err, sizeof err));
  TEST_ASSERT_EQUAL_MEMORY(&defaults, &cfg, sizeof cfg);
  remove("defaults.cfg");
}

/* The handle API Python uses: a heap config read and set by key, each key's declaration. */
static void test_config_load_KeysAreReadByNameWithTheirDeclaration(void) {
  poursim_config_t *c = poursim_config_new(NULL);
  TEST_ASSERT_NOT_NULL(c);
  double v = 0.0;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_get(c, "n_particles", &v, err, sizeof err));
  TEST_ASSERT_EQUAL_DOUBLE(150.0, v);
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_set(c, "tau_max", "12.5", err, sizeof err));
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_get(c, "tau_max", &v, err, sizeof err));
  TEST_ASSERT_EQUAL_DOUBLE(12.5, v);
  poursim_config_t *copy = poursim_config_new(c);
  TEST_ASSERT_EQUAL_MEMORY(c, copy, sizeof *c);
  poursim_config_free(copy);
  poursim_config_free(c);
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_config_get(&cfg, "sead", &v, err, sizeof err));
  TEST_ASSERT_NOT_NULL(strstr(err, "unknown config key 'sead'"));
  int integer = -1;
  double lo = 0, hi = 0, def = 0;
  const char *unit = NULL, *doc = NULL;
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_key_info("command_latency_ticks", &integer, &lo, &hi, &def, &unit, &doc));
  TEST_ASSERT_EQUAL_INT(1, integer);
  TEST_ASSERT_EQUAL_DOUBLE(1.0, lo);
  TEST_ASSERT_EQUAL_DOUBLE(100.0, hi);
  TEST_ASSERT_EQUAL_DOUBLE(1.0, def);
  TEST_ASSERT_EQUAL_STRING("steps", unit);
  TEST_ASSERT_TRUE(strlen(doc) > 10);
  TEST_ASSERT_EQUAL_INT(POURSIM_OK, poursim_config_key_info("tau_max", &integer, NULL, NULL, NULL, NULL, NULL));
  TEST_ASSERT_EQUAL_INT(0, integer);
  TEST_ASSERT_EQUAL_INT(POURSIM_EINVAL, poursim_config_key_info("sead", NULL, NULL, NULL, NULL, NULL, NULL));
  TEST_ASSERT_NULL(poursim_config_key(-1));
  TEST_ASSERT_NULL(poursim_config_key(100000));
}

/* /dev/zero: refused at the size cap, not read until memory runs out. */
static void test_config_load_RefusesAnEndlessFile(void) {
  expect_error(poursim_config_load("/dev/zero", &cfg, err, sizeof err), "/dev/zero", "larger than 1048576 bytes");
}

/* "seed = 7\0JUNK" is refused, not read as seed 7: a NUL byte is not text. */
static void test_config_load_RefusesNulBytes(void) {
  static const char text[] = "friction = 0.1\nseed = 7\0JUNK\n";
  expect_error(load_text("nul.cfg", text, sizeof text - 1), "nul.cfg:2:", "NUL byte");
}

/* A key set twice is refused, not settled by the last one. */
static void test_config_load_RefusesDuplicateKeys(void) {
  static const char text[] = "seed = 7\nfriction = 0.1\n  seed=8\n";
  expect_error(load_text("dup.cfg", text, sizeof text - 1), "dup.cfg:3:", "seed is set twice (first on line 1)");
}

static void test_config_load_NamesFileAndLineInEveryError(void) {
  static const char bad_line[] = "seed = 7\n\nno equals sign\n";
  expect_error(load_text("line.cfg", bad_line, sizeof bad_line - 1), "line.cfg:3:", "expected 'key = value'");
  static const char bad_key[] = "sead = 7\n";
  expect_error(load_text("key.cfg", bad_key, sizeof bad_key - 1), "key.cfg:1:", "unknown config key 'sead'");
  static const char bad_value[] = "# c\nfriction = 1e999\n";
  expect_error(load_text("value.cfg", bad_value, sizeof bad_value - 1), "value.cfg:2:", "friction");
  /* A rule across keys: the line of the key the rule names first. */
  static const char cross[] = "seed = 3\nfill_depth = 0.32\n"; /* overflows the 32.5 cm bucket */
  expect_error(load_text("cross.cfg", cross, sizeof cross - 1), "cross.cfg:2:", "fill_depth");
  expect_error(poursim_config_load("/nonexistent/x.cfg", &cfg, err, sizeof err), "/nonexistent/x.cfg", "cannot read");
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_config_load_ReadsTheShippedConfig);
  RUN_TEST(test_config_load_ShippedConfigIsTheGeneratedDefaults);
  RUN_TEST(test_config_load_KeysAreReadByNameWithTheirDeclaration);
  RUN_TEST(test_config_load_RefusesAnEndlessFile);
  RUN_TEST(test_config_load_RefusesNulBytes);
  RUN_TEST(test_config_load_RefusesDuplicateKeys);
  RUN_TEST(test_config_load_NamesFileAndLineInEveryError);
  return UNITY_END();
}
