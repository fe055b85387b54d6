// SPDX-License-Identifier: MIT
// poursim::run_episode: what it records, its figures, and the errors it reports when the controller or the
// world stops the episode.
#include <cmath>
#include <string>

#include "controllers.hpp"
#include "episode_run.hpp"
#include "unity.h"

extern "C" {
void setUp(void) {}
void tearDown(void) {}
}

namespace {

// A constant command; fails (as a controller across LCM that stopped answering) from step fail_at on.
class Constant : public poursim::Controller {
 public:
  explicit Constant(double command, int fail_at = -1) : command_(command), fail_at_(fail_at) {}
  std::string name() const override { return "constant"; }
  void reset(uint32_t seed) override {
    seed_ = seed;
    calls_ = 0;
  }
  double command(const poursim_obs_t &) override {
    ++calls_;
    return failed() ? 0.0 : command_;
  }
  int action() const override { return 4; }
  bool failed() const override { return fail_at_ >= 0 && calls_ > fail_at_; }
  std::string failure() const override { return "no answer"; }
  uint32_t seed_ = 0;
  int calls_ = 0;

 private:
  double command_;
  int fail_at_;
};

poursim_world_t *make_world(poursim_config_t cfg) {
  char err[POURSIM_ERR_LEN];
  poursim_world_t *w = poursim_create(&cfg, err, sizeof err);
  TEST_ASSERT_NOT_NULL_MESSAGE(w, err);
  return w;
}

poursim_config_t short_config() {
  poursim_config_t cfg = poursim_default_config();
  cfg.episode_s = 0.2;
  return cfg;
}

} // namespace

static void test_episode_run_RecordsEveryStepAndTheFramesAskedFor(void) {
  poursim_world_t *w = make_world(short_config());
  Constant ctl(0.5);
  poursim::Recorder rec;
  rec.steps = true;
  rec.frame_every = 80;
  poursim::Episode e = poursim::run_episode(w, ctl, 3u, poursim_default_reward(), &rec);
  TEST_ASSERT_EQUAL_STRING("", e.error.c_str());
  TEST_ASSERT_EQUAL_UINT32(3u, e.seed);
  TEST_ASSERT_EQUAL_UINT32(3u, ctl.seed_);
  TEST_ASSERT_EQUAL_INT(200, ctl.calls_);
  TEST_ASSERT_EQUAL_INT(200, e.m.n_steps);
  TEST_ASSERT_EQUAL_size_t(200, rec.samples.size());
  TEST_ASSERT_EQUAL_UINT32(1u, rec.samples.front().obs.step);
  TEST_ASSERT_EQUAL_UINT32(200u, rec.samples.back().obs.step);
  TEST_ASSERT_EQUAL_INT(4, rec.samples.back().action);
  TEST_ASSERT_EQUAL_DOUBLE(0.5 * poursim_world_config(w)->tau_max, rec.samples.back().obs.torque);
  // The start, then steps 80 and 160.
  const int n = poursim_particle_count(w);
  TEST_ASSERT_EQUAL_size_t(3, rec.frames.size());
  TEST_ASSERT_EQUAL_size_t(3, rec.frame_t.size());
  TEST_ASSERT_EQUAL_size_t(3, rec.frame_theta.size());
  TEST_ASSERT_EQUAL_size_t(static_cast<size_t>(2 * n), rec.frames[2].size());
  TEST_ASSERT_EQUAL_size_t(static_cast<size_t>(n), rec.radius.size());
  TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.16, rec.frame_t[2]);
  TEST_ASSERT_TRUE(rec.radius[0] > 0.0f);
  // The figures are the last observation's; each sample's reward is the reward's of its observation.
  TEST_ASSERT_EQUAL_DOUBLE(rec.samples.back().obs.v_target, e.m.poured);
  for (const poursim::Sample &s : rec.samples)
    TEST_ASSERT_EQUAL_DOUBLE(1.0 * s.obs.v_target - 5.0 * s.obs.v_spill, s.reward);
  TEST_ASSERT_EQUAL_DOUBLE(rec.samples.back().obs.v_rotating, e.m.remaining);
  poursim_destroy(w);
}

static void test_episode_run_IsTheSameWithAndWithoutARecorder(void) {
  poursim_world_t *w = make_world(short_config());
  Constant ctl(1.0);
  poursim::Recorder rec;
  rec.steps = true;
  rec.frame_every = 7;
  const poursim::Episode a = poursim::run_episode(w, ctl, 5u, poursim_default_reward(), &rec);
  const uint64_t hash_a = poursim_trajectory_hash(w);
  const poursim::Episode b = poursim::run_episode(w, ctl, 5u, poursim_default_reward(), nullptr);
  TEST_ASSERT_EQUAL_STRING("", b.error.c_str());
  TEST_ASSERT_EQUAL_DOUBLE(a.m.ret, b.m.ret);
  TEST_ASSERT_EQUAL_DOUBLE(a.m.peak_omega, b.m.peak_omega);
  TEST_ASSERT_EQUAL_DOUBLE(a.m.poured, b.m.poured);
  TEST_ASSERT_EQUAL_UINT64(hash_a, poursim_trajectory_hash(w));
  poursim_destroy(w);
}

static void test_episode_run_ReportsTheWorldsErrorWhenAStepFails(void) {
  poursim_config_t cfg = poursim_default_config();
  cfg.fluid_stiffness = 1e5; // stable at 1 ms, not at 5 ms (test_liquid's blow-up)
  cfg.dt = 0.005;
  poursim_world_t *w = make_world(cfg);
  Constant ctl(0.5);
  poursim::Recorder rec;
  rec.steps = true;
  poursim::Episode e = poursim::run_episode(w, ctl, cfg.seed, poursim_default_reward(), &rec);
  TEST_ASSERT_NOT_EQUAL_MESSAGE(std::string::npos, e.error.find("blew up"), e.error.c_str());
  TEST_ASSERT_EQUAL_STRING(poursim_world_error(w), e.error.c_str());
  TEST_ASSERT_TRUE(rec.samples.size() < 2000u); // stopped at the failing step
  poursim_destroy(w);
}

static void test_episode_run_ReportsARefusedCommand(void) {
  poursim_world_t *w = make_world(short_config());
  Constant ctl(NAN);
  poursim::Episode e = poursim::run_episode(w, ctl, 1u, poursim_default_reward(), nullptr);
  TEST_ASSERT_FALSE(e.error.empty()); // the world keeps no message for a refused argument
  TEST_ASSERT_NOT_EQUAL_MESSAGE(std::string::npos, e.error.find("poursim_step"), e.error.c_str());
  TEST_ASSERT_EQUAL_INT(1, ctl.calls_);
  poursim_destroy(w);
}

static void test_episode_run_StopsWithTheControllersFailure(void) {
  poursim_world_t *w = make_world(short_config());
  Constant ctl(0.5, 10);
  poursim::Recorder rec;
  rec.steps = true;
  poursim::Episode e = poursim::run_episode(w, ctl, 1u, poursim_default_reward(), &rec);
  TEST_ASSERT_EQUAL_STRING("no answer", e.error.c_str());
  TEST_ASSERT_EQUAL_size_t(10, rec.samples.size()); // the failed command is not stepped
  poursim_destroy(w);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_episode_run_RecordsEveryStepAndTheFramesAskedFor);
  RUN_TEST(test_episode_run_IsTheSameWithAndWithoutARecorder);
  RUN_TEST(test_episode_run_ReportsTheWorldsErrorWhenAStepFails);
  RUN_TEST(test_episode_run_ReportsARefusedCommand);
  RUN_TEST(test_episode_run_StopsWithTheControllersFailure);
  return UNITY_END();
}
