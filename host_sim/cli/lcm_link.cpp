// SPDX-License-Identifier: MIT
#include "lcm_link.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sys/select.h>

#include <lcm/lcm.h>

#include "pour/command_t.hpp"
#include "pour/particles_t.hpp"
#include "pour/plant_truth_t.hpp"
#include "pour/sensor_sample_t.hpp"
#include "pour/torque_t.hpp"
#include "pour_lcm/channels.h"

namespace poursim {

namespace {

int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

int64_t wall_us() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000LL + ts.tv_nsec / 1000;
}

void sleep_until_ns(int64_t t_ns) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / 1000000000LL);
  ts.tv_nsec = static_cast<long>(t_ns % 1000000000LL);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

constexpr int64_t kPeriodNs = 1000000;

// Encodes a generated C++ message and publishes it with the C API. (LCM's C++ wrapper is avoided: its
// subscription casts trip UBSan's vptr check.)
template <typename Msg>
int publish(lcm_t *lcm, const char *channel, const Msg &msg) {
  std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
  const int n = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return n < 0 ? n : lcm_publish(lcm, channel, buf.data(), static_cast<unsigned>(n));
}
constexpr size_t kRing = 4096; // send times of recent samples, by seq modulo the ring size

} // namespace

struct LcmLink::Impl {
  LcmLinkDef def;
  lcm_t *lcm = nullptr;
  LcmLinkStats stats;
  std::array<int64_t, kRing> sent_ns{};  // publish time of seq % kRing
  std::array<int64_t, kRing> sent_seq{}; // which seq the slot holds
  int episode = 0;
  int64_t waiting_seq = -1;   // the sample whose answer the current tick waits for
  bool got_waited = false;
  int16_t answer_q15 = 0;     // torque of the latest accepted answer
  int answer_action = -1;     // its action index
  int64_t answer_ns = 0;      // when it arrived (real time: age check)
  bool have_answer = false;
  int64_t t0_ns = 0;          // real time: slot of tick 0
  int64_t next_particles_step = 0;
  pour::sensor_sample_t last_sample{};

  explicit Impl(const LcmLinkDef &d) : def(d), lcm(lcm_create(d.url.empty() ? POUR_LCM_DEFAULT_URL : d.url.c_str())) {}
  ~Impl() {
    if (lcm != nullptr) {
      lcm_destroy(lcm);
    }
  }
  Impl(const Impl &) = delete;
  Impl &operator=(const Impl &) = delete;

  static void on_torque_c(const lcm_recv_buf_t *rbuf, const char * /*channel*/, void *user) {
    static_cast<Impl *>(user)->on_torque(rbuf);
  }

  void on_torque(const lcm_recv_buf_t *rbuf) {
    pour::torque_t msg;
    const int n = msg.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size));
    if (n < 0 || static_cast<uint32_t>(n) != rbuf->data_size) {
      stats.dropped++;
      return;
    }
    const int64_t now = mono_ns();
    const size_t slot = static_cast<size_t>(msg.seq) % kRing;
    const bool ours = msg.episode == episode && msg.seq >= 0 && sent_seq[slot] == msg.seq && sent_ns[slot] != 0;
    if (!ours) {
      stats.stale_answers++;
      return;
    }
    if (msg.seq == waiting_seq && !got_waited) {
      got_waited = true;
      stats.on_time++;
    } else if (msg.seq < waiting_seq || (!def.lockstep && msg.seq != waiting_seq)) {
      // Real time: the answer to an earlier tick, whose torque was already chosen.
      stats.late++;
    } else {
      stats.stale_answers++; // a duplicate (resend) answer
      return;
    }
    stats.answers++;
    stats.rtt_us.push_back(static_cast<int32_t>(std::min<int64_t>((now - sent_ns[slot]) / 1000, INT32_MAX)));
    sent_ns[slot] = 0; // one round trip per sample
    // Real time uses the newest answer, whichever sample it answers; lockstep only the awaited one.
    if (!def.lockstep || msg.seq == waiting_seq) {
      answer_q15 = msg.torque_q15;
      stats.last_mode = msg.mode;
      stats.controller_weights_hash = static_cast<uint32_t>(msg.weights_hash);
      stats.last_faults = msg.faults;
      if (msg.mode >= 2) {
        stats.fault_answers++;
      }
      answer_action = msg.action;
      answer_ns = now;
      have_answer = true;
    }
  }

  // Handles messages until the awaited answer arrived or deadline_ns passed; returns got_waited.
  bool pump_until(int64_t deadline_ns) {
    const int fd = lcm_get_fileno(lcm);
    while (!got_waited) {
      const int64_t left_ns = deadline_ns - mono_ns();
      if (left_ns <= 0) {
        break;
      }
      fd_set fds;
      FD_ZERO(&fds);
      FD_SET(fd, &fds);
      timeval tv{};
      tv.tv_sec = static_cast<time_t>(left_ns / 1000000000LL);
      tv.tv_usec = static_cast<suseconds_t>((left_ns % 1000000000LL) / 1000);
      const int r = select(fd + 1, &fds, nullptr, nullptr, &tv);
      if (r < 0 && errno != EINTR) {
        break;
      }
      if (r > 0) {
        lcm_handle(lcm);
      }
    }
    return got_waited;
  }

  void poll_all() {
    const int fd = lcm_get_fileno(lcm);
    for (int i = 0; i < 10000; i++) {
      fd_set fds;
      FD_ZERO(&fds);
      FD_SET(fd, &fds);
      timeval tv{};
      if (select(fd + 1, &fds, nullptr, nullptr, &tv) <= 0) {
        break;
      }
      lcm_handle(lcm);
    }
  }

  // The controller's policy must be the one host_sim was given (else the pour is not the one asked for).
  bool weights_ok(std::string *err) const {
    if (def.expected_weights_hash == 0 || stats.controller_weights_hash == 0 ||
        stats.controller_weights_hash == def.expected_weights_hash) {
      return true;
    }
    if (err != nullptr) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "pour_controller runs weights with content hash 0x%08x, but the policy given has 0x%08x: "
                    "rebuild pour_controller with that weights.h (CMake POUR_WEIGHTS)",
                    static_cast<unsigned>(stats.controller_weights_hash),
                    static_cast<unsigned>(def.expected_weights_hash));
      *err = buf;
    }
    return false;
  }

  // The truth first, for the bench's tools only; then the sample the controller answers.
  void publish_sample(int64_t seq, const pour::plant_truth_t &truth) {
    publish(lcm, POUR_LCM_CHANNEL_TRUTH, truth);
    const size_t slot = static_cast<size_t>(seq) % kRing;
    sent_seq[slot] = seq;
    sent_ns[slot] = mono_ns();
    publish(lcm, POUR_LCM_CHANNEL_SENSORS, last_sample);
  }
};

LcmLink::LcmLink(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
LcmLink::~LcmLink() = default;

std::unique_ptr<LcmLink> LcmLink::open(const LcmLinkDef &def, std::string *err) {
  auto impl = std::make_unique<Impl>(def);
  if (impl->lcm == nullptr) {
    if (err != nullptr) {
      *err = "cannot open LCM at '" + (def.url.empty() ? std::string(POUR_LCM_DEFAULT_URL) : def.url) + "'";
    }
    return nullptr;
  }
  if (def.answer_timeout_ms < 1 || def.resend_ms < 1 || def.rt_budget_us < 0 || def.rt_budget_us > 1000 ||
      def.rt_safe_after_ms < 1 || def.particles_period_ms < 0) {
    if (err != nullptr) {
      *err = "LCM link: a timeout or period is out of range";
    }
    return nullptr;
  }
  if (lcm_subscribe(impl->lcm, POUR_LCM_CHANNEL_TORQUE, &Impl::on_torque_c, impl.get()) == nullptr) {
    if (err != nullptr) {
      *err = "cannot subscribe to " POUR_LCM_CHANNEL_TORQUE;
    }
    return nullptr;
  }
  impl->stats.rtt_us.reserve(1 << 16);
  return std::unique_ptr<LcmLink>(new LcmLink(std::move(impl)));
}

bool LcmLink::exchange(int episode, const poursim_obs_t &obs, int16_t *torque_q15, std::string *err) {
  Impl &s = *impl_;
  const int64_t seq = obs.step;
  if (episode != s.episode || seq == 0) {
    // A new episode: earlier answers mean nothing to it.
    s.episode = episode;
    s.sent_ns.fill(0);
    s.have_answer = false;
    s.answer_q15 = 0;
    s.answer_action = -1;
    s.next_particles_step = 0;
    if (!s.def.lockstep && seq == 0) {
      s.t0_ns = 0;
    }
  }
  // What the rig's sensors read, exactly as the in-process controller is handed them (seq = step); the
  // counts fit int32 (encoder_bits <= 24).
  pour::sensor_sample_t &m = s.last_sample;
  m.seq = seq;
  m.episode = episode;
  m.encoder = static_cast<int32_t>(obs.encoder);
  m.scale_rotating_g = obs.scale_rotating_g;
  m.scale_target_g = obs.scale_target_g;
  pour::plant_truth_t truth;
  truth.seq = seq;
  truth.episode = episode;
  truth.theta = obs.theta;
  truth.omega = obs.omega;
  truth.v_rotating = obs.v_rotating;
  truth.v_target = obs.v_target;
  truth.v_spill = obs.v_spill;
  truth.motor_torque = obs.motor_torque;
  double x[POURSIM_N_FEATURES] = {};
  if (s.def.truth_obs)
    poursim_features(&s.def.truth_norm, obs.theta, obs.omega, obs.v_rotating, obs.v_target, obs.v_spill, x);
  for (int i = 0; i < 5; i++) truth.obs[i] = static_cast<float>(x[i]);
  s.waiting_seq = seq;
  s.got_waited = false;

  if (s.def.lockstep) {
    m.utime = truth.utime = std::llround(obs.t * 1e6);
    s.stats.samples_sent++;
    s.publish_sample(seq, truth);
    const int64_t start = mono_ns();
    const int64_t give_up = start + static_cast<int64_t>(s.def.answer_timeout_ms) * 1000000LL;
    int64_t resend_at = start + static_cast<int64_t>(s.def.resend_ms) * 1000000LL;
    while (!s.pump_until(std::min(resend_at, give_up))) {
      if (mono_ns() >= give_up) {
        if (err != nullptr) {
          char buf[256];
          std::snprintf(buf, sizeof buf,
                        "no answer on %s to %s seq %lld (episode %d) within %d ms: is pour_controller "
                        "running (--lockstep) on the same LCM URL?",
                        POUR_LCM_CHANNEL_TORQUE, POUR_LCM_CHANNEL_SENSORS, static_cast<long long>(seq), episode,
                        s.def.answer_timeout_ms);
          *err = buf;
        }
        return false;
      }
      // Lost on the way (or the controller started late): the controller answers a resend again.
      s.stats.resends++;
      const size_t slot = static_cast<size_t>(seq) % kRing;
      const int64_t first = s.sent_ns[slot];
      publish(s.lcm, POUR_LCM_CHANNEL_SENSORS, m);
      s.sent_ns[slot] = first; // the round trip counts from the first publish
      resend_at = mono_ns() + static_cast<int64_t>(s.def.resend_ms) * 1000000LL;
    }
    *torque_q15 = s.answer_q15;
    return s.weights_ok(err);
  }

  // Real time: tick k owns the wall-clock slot [t0 + k ms, t0 + (k+1) ms).
  if (s.t0_ns == 0) {
    s.t0_ns = mono_ns() - static_cast<int64_t>(seq) * kPeriodNs;
  }
  const int64_t slot_ns = s.t0_ns + static_cast<int64_t>(seq) * kPeriodNs;
  sleep_until_ns(slot_ns);
  const int64_t late_ns = mono_ns() - slot_ns;
  if (late_ns / 1000 > s.stats.late_max_us) {
    s.stats.late_max_us = late_ns / 1000;
  }
  if (late_ns > kPeriodNs) {
    s.stats.overruns++;
  }
  m.utime = truth.utime = wall_us();
  s.stats.samples_sent++;
  s.publish_sample(seq, truth);
  s.poll_all();
  s.pump_until(slot_ns + static_cast<int64_t>(s.def.rt_budget_us) * 1000);
  const int64_t now = mono_ns();
  if (s.have_answer && now - s.answer_ns <= static_cast<int64_t>(s.def.rt_safe_after_ms) * 1000000LL) {
    *torque_q15 = s.answer_q15;
  } else {
    *torque_q15 = 0;
    s.stats.safe_ticks++;
  }
  return s.have_answer ? s.weights_ok(err) : true;
}

void LcmLink::maybe_publish_particles(const poursim_world_t *world, const poursim_obs_t &obs) {
  Impl &s = *impl_;
  if (s.def.particles_period_ms <= 0 || static_cast<int64_t>(obs.step) < s.next_particles_step) {
    return;
  }
  s.next_particles_step = static_cast<int64_t>(obs.step) + s.def.particles_period_ms;
  const poursim_config_t *c = poursim_world_config(world);
  const int n = poursim_particle_count(world);
  std::vector<float> xy(static_cast<size_t>(2 * n)), r(static_cast<size_t>(n));
  const int got = poursim_particles(world, xy.data(), r.data(), n);
  pour::particles_t m;
  m.utime = s.def.lockstep ? std::llround(obs.t * 1e6) : wall_us();
  m.seq = obs.step;
  m.theta = obs.theta;
  m.pivot_x = 0.0f;
  m.pivot_y = static_cast<float>(c->pivot_height);
  m.target_x = static_cast<float>(c->target_dx);
  m.target_y = static_cast<float>(0.5 * c->bucket_height);
  m.bucket_inner_width = static_cast<float>(c->bucket_inner_width);
  m.bucket_height = static_cast<float>(c->bucket_height);
  m.bucket_wall = static_cast<float>(c->bucket_wall);
  m.theta_max = c->theta_max;
  m.n = got;
  m.x.resize(static_cast<size_t>(got));
  m.y.resize(static_cast<size_t>(got));
  m.r.assign(r.begin(), r.begin() + got);
  for (int i = 0; i < got; i++) {
    m.x[static_cast<size_t>(i)] = xy[static_cast<size_t>(2 * i)];
    m.y[static_cast<size_t>(i)] = xy[static_cast<size_t>(2 * i + 1)];
  }
  publish(s.lcm, POUR_LCM_CHANNEL_PARTICLES, m);
  s.stats.particles_sent++;
}

void LcmLink::drain(int wait_ms) {
  Impl &s = *impl_;
  s.waiting_seq = -1;
  s.got_waited = false;
  s.pump_until(mono_ns() + static_cast<int64_t>(wait_ms) * 1000000LL);
}

void LcmLink::request_new_run() {
  pour::command_t m{};
  m.utime = wall_us();
  m.clear_faults = 1;
  m.stop = 1;
  m.reset = 1;
  publish(impl_->lcm, POUR_LCM_CHANNEL_COMMAND, m);
}

int LcmLink::last_action() const { return impl_->answer_action; }

const LcmLinkStats &LcmLink::stats() const { return impl_->stats; }
const LcmLinkDef &LcmLink::def() const { return impl_->def; }

void LcmLink::rtt_percentiles(double *median_us, double *p99_us) const {
  std::vector<int32_t> v = impl_->stats.rtt_us;
  if (v.empty()) {
    *median_us = 0.0;
    *p99_us = 0.0;
    return;
  }
  std::sort(v.begin(), v.end());
  auto pick = [&v](double q) {
    const size_t i = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1;
    return static_cast<double>(v[std::min(i, v.size() - 1)]);
  };
  *median_us = pick(0.5);
  *p99_us = pick(0.99);
}

std::string LcmLink::summary() const {
  const LcmLinkStats &st = impl_->stats;
  double med = 0.0, p99 = 0.0;
  rtt_percentiles(&med, &p99);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "lcm %s: samples %lld answers %lld on_time %lld late %lld missing %lld resends %lld "
                "dropped %lld stale_answers %lld safe_ticks %lld overruns %lld late_max_us %lld particles %lld "
                "rtt_median_us %.0f rtt_p99_us %.0f fault_answers %lld controller_faults 0x%04x",
                impl_->def.lockstep ? "lockstep" : "realtime", static_cast<long long>(st.samples_sent),
                static_cast<long long>(st.answers), static_cast<long long>(st.on_time), static_cast<long long>(st.late),
                static_cast<long long>(st.samples_sent - st.on_time - st.late), static_cast<long long>(st.resends),
                static_cast<long long>(st.dropped), static_cast<long long>(st.stale_answers),
                static_cast<long long>(st.safe_ticks), static_cast<long long>(st.overruns),
                static_cast<long long>(st.late_max_us), static_cast<long long>(st.particles_sent), med, p99,
                static_cast<long long>(st.fault_answers), static_cast<unsigned>(st.last_faults & 0xffff));
  return buf;
}

std::unique_ptr<LcmController> LcmController::open(const LcmLinkDef &def, std::string *err) {
  std::unique_ptr<LcmLink> link = LcmLink::open(def, err);
  if (!link) {
    return nullptr;
  }
  return std::unique_ptr<LcmController>(new LcmController(std::move(link)));
}

std::string LcmController::name() const {
  const LcmLinkDef &d = link_->def();
  return std::string("pour_controller over LCM (") + (d.lockstep ? "lockstep" : "real time") + ", " +
         (d.url.empty() ? POUR_LCM_DEFAULT_URL : d.url) + ")";
}

void LcmController::reset(uint32_t /*seed*/) {
  episode_++;
  link_->request_new_run();
}

double LcmController::command(const poursim_obs_t &obs) {
  if (failure_status_ != 0) {
    return 0.0;
  }
  int16_t q15 = 0;
  std::string err;
  if (!link_->exchange(episode_, obs, &q15, &err)) {
    const bool answered = link_->stats().answers > 0 && link_->stats().controller_weights_hash != 0;
    failure_ = err;
    failure_status_ = answered && link_->def().expected_weights_hash != link_->stats().controller_weights_hash ? 4 : 3;
    return 0.0;
  }
  if (world_ != nullptr) {
    link_->maybe_publish_particles(world_, obs);
  }
  const LcmLinkStats &st = link_->stats();
  if (st.last_mode >= 2 && !warned_) {
    // Latched faults need an operator's clear: say so instead of pouring silently with safe torque.
    std::fprintf(stderr,
                 "host_sim: warning: pour_controller answers in %s (faults 0x%04x): it commands safe torque until "
                 "its faults are cleared (pour-lcm-cmd --clear)\n",
                 st.last_mode == 3 ? "E-STOP" : "FAULT", static_cast<unsigned>(st.last_faults & 0xffff));
    warned_ = true;
  }
  // Exactly as the in-process firmware controller turns its output into an action.
  return q15 / 32768.0;
}

} // namespace poursim
