// SPDX-License-Identifier: MIT
// host_sim's output writers: the JSON string writer (every string host_sim writes into JSON goes through it),
// the CSV of every step and the trajectory JSON pour-render reads. With a file argument, the trajectory of
// test_render_json_WritesTheRecorderAsOneObject is also written there (ctest's sim_test_outputs_json_parses
// loads it with Python's json module).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "outputs.hpp"
#include "unity.h"

extern "C" {
void setUp(void) {}
void tearDown(void) {}
}

namespace {

const char *g_json_path = nullptr;

// What f received, after it is closed.
struct Capture {
  char *buf = nullptr;
  size_t len = 0;
  std::FILE *f = open_memstream(&buf, &len);
  std::string text() {
    std::fclose(f);
    f = nullptr;
    std::string s(buf, len);
    std::free(buf);
    buf = nullptr;
    return s;
  }
  ~Capture() {
    if (f != nullptr) std::fclose(f);
    std::free(buf);
  }
};

poursim_obs_t obs(uint32_t step, double theta, double v_target, double torque) {
  poursim_obs_t o{};
  o.step = step;
  o.t = 0.001 * step;
  o.theta = theta;
  o.omega = -1.25;
  o.v_rotating = 1.0 - v_target;
  o.v_target = v_target;
  o.v_spill = 0.05;
  o.v_flight = 0.0;
  o.torque = torque;
  return o;
}

// Two steps, two circles, frames at the start and after the second step.
poursim::Recorder two_step_recording() {
  poursim::Recorder rec;
  rec.steps = true;
  rec.frame_every = 2;
  rec.samples = {{obs(1, 0.5, 0.25, 10.0), 3, 0.25 - 0.05}, {obs(2, 0.625, 0.5, -20.0), -1, 0.5 - 0.05}};
  rec.radius = {0.01f, 0.0125f};
  rec.frames = {{0.0f, 0.5f, 0.25f, 0.5f}, {0.0f, 0.25f, 0.5f, 0.125f}};
  rec.frame_t = {0.0, 0.002};
  rec.frame_theta = {0.0, 0.625};
  return rec;
}

poursim_episode_t figures() {
  poursim_episode_t m{};
  m.poured = 0.5;
  m.spilled = 0.05;
  m.finish_time = 0.002;
  return m;
}

} // namespace

static void test_json_quote_EscapesQuotesBackslashesAndControlCharacters(void) {
  TEST_ASSERT_EQUAL_STRING("\"firmware (greedy)\"", poursim::json_quote("firmware (greedy)").c_str());
  TEST_ASSERT_EQUAL_STRING("\"\"", poursim::json_quote("").c_str());
  TEST_ASSERT_EQUAL_STRING("\"a\\\"b\\\\c\"", poursim::json_quote("a\"b\\c").c_str());
  TEST_ASSERT_EQUAL_STRING("\"line\\u000anext\\u0009tab\\u0001\\u007f\"",
                           poursim::json_quote("line\nnext\ttab\x01\x7f").c_str());
  TEST_ASSERT_EQUAL_STRING("\"\xce\xb8 rad/s\"", poursim::json_quote("\xce\xb8 rad/s").c_str()); // UTF-8 kept
}

static void test_csv_WritesTheHeaderThenOneLinePerSample(void) {
  Capture c;
  poursim::write_csv_header(c.f);
  poursim::write_csv_episode(c.f, 2, 7u, two_step_recording().samples, 20.0);
  TEST_ASSERT_EQUAL_STRING(
      "episode,seed,step,t_s,theta_rad,omega_rad_s,v_rotating,v_target,v_spill,v_flight,action,torque_nm,"
      "torque_frac,reward\n"
      "2,7,1,0.001,0.500000,-1.250000,0.750000,0.250000,0.050000,0.000000,3,10.0000,0.500000,0.200000\n"
      "2,7,2,0.002,0.625000,-1.250000,0.500000,0.500000,0.050000,0.000000,-1,-20.0000,-1.000000,0.450000\n",
      c.text().c_str());
}

static void test_csv_AnEpisodeWithoutSamplesWritesNothing(void) {
  Capture c;
  poursim::write_csv_episode(c.f, 1, 1u, {}, 20.0);
  TEST_ASSERT_EQUAL_STRING("", c.text().c_str());
}

static void test_render_json_WritesTheRecorderAsOneObject(void) {
  poursim_config_t config = poursim_default_config();
  config.dt = 0.04; // a frame every 2 steps of 40 ms: 12.5 frames/s
  const std::string title = "policy \"a\\b\"\nsampled";
  Capture c;
  poursim::write_render_json(c.f, config, two_step_recording(), title, figures());
  char scene[512];
  std::snprintf(scene, sizeof scene,
                "\"scene\": {\"inner_width\": %.5f, \"height\": %.5f, \"wall\": %.5f, \"pivot_x\": 0.0, "
                "\"pivot_y\": %.5f, \"target_x\": %.5f, \"theta_max\": %.5f},\n",
                config.bucket_inner_width, config.bucket_height, config.bucket_wall, config.pivot_height,
                config.target_dx, config.theta_max);
  const std::string want =
      std::string("{\"fps\": 12.500, \"title\": \"policy \\\"a\\\\b\\\"\\u000asampled\", \"poured\": 0.5000, "
                  "\"spilled\": 0.0500, \"finish_s\": 0.002,\n") +
      scene +
      "\"radius\": [0.01000,0.01250],\n"
      "\"series\": {\"t\": [0.001], \"theta\": [0.5], \"v_rotating\": [0.75], \"v_target\": [0.25], "
      "\"v_spill\": [0.05], \"torque\": [10]},\n"
      "\"frames\": [\n"
      "{\"t\": 0.000, \"theta\": 0.00000, \"xy\": [0.0000,0.5000,0.2500,0.5000]},\n"
      "{\"t\": 0.002, \"theta\": 0.62500, \"xy\": [0.0000,0.2500,0.5000,0.1250]}]}\n";
  TEST_ASSERT_EQUAL_STRING(want.c_str(), c.text().c_str());
  if (g_json_path != nullptr) {
    std::string err;
    TEST_ASSERT_TRUE_MESSAGE(poursim::save_render_json(g_json_path, config, two_step_recording(), title, figures(), &err),
                             err.c_str());
  }
}

static void test_render_json_SaveNamesTheFileItCannotWrite(void) {
  std::string err;
  TEST_ASSERT_FALSE(poursim::save_render_json("/nonexistent-folder/x.json", poursim_default_config(),
                                              two_step_recording(), "t", figures(), &err));
  TEST_ASSERT_NOT_EQUAL(std::string::npos, err.find("/nonexistent-folder/x.json"));
}

int main(int argc, char **argv) {
  if (argc > 1) g_json_path = argv[1];
  UNITY_BEGIN();
  RUN_TEST(test_json_quote_EscapesQuotesBackslashesAndControlCharacters);
  RUN_TEST(test_csv_WritesTheHeaderThenOneLinePerSample);
  RUN_TEST(test_csv_AnEpisodeWithoutSamplesWritesNothing);
  RUN_TEST(test_render_json_WritesTheRecorderAsOneObject);
  RUN_TEST(test_render_json_SaveNamesTheFileItCannotWrite);
  return UNITY_END();
}
