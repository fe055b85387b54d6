// SPDX-License-Identifier: MIT
// host_sim's output helpers: the JSON string writer (every string host_sim writes into JSON goes through it).
#include <string>

#include "outputs.hpp"
#include "unity.h"

extern "C" {
void setUp(void) {}
void tearDown(void) {}
}

static void test_json_quote_EscapesQuotesBackslashesAndControlCharacters(void) {
  TEST_ASSERT_EQUAL_STRING("\"firmware (greedy)\"", poursim::json_quote("firmware (greedy)").c_str());
  TEST_ASSERT_EQUAL_STRING("\"\"", poursim::json_quote("").c_str());
  TEST_ASSERT_EQUAL_STRING("\"a\\\"b\\\\c\"", poursim::json_quote("a\"b\\c").c_str());
  TEST_ASSERT_EQUAL_STRING("\"line\\u000anext\\u0009tab\\u0001\\u007f\"",
                           poursim::json_quote("line\nnext\ttab\x01\x7f").c_str());
  TEST_ASSERT_EQUAL_STRING("\"\xce\xb8 rad/s\"", poursim::json_quote("\xce\xb8 rad/s").c_str()); // UTF-8 kept
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_json_quote_EscapesQuotesBackslashesAndControlCharacters);
  return UNITY_END();
}
