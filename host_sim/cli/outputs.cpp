// SPDX-License-Identifier: MIT
#include "outputs.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdlib>
#include <cstring>

namespace poursim {

namespace {

// The temporaries open at a signal: a fixed table (a handler may not allocate), unlinked by the handler.
constexpr int kMaxTemps = 8;
char g_temps[kMaxTemps][PATH_MAX];
volatile sig_atomic_t g_used[kMaxTemps];

void remove_temps() {
  for (int i = 0; i < kMaxTemps; ++i)
    if (g_used[i]) unlink(g_temps[i]);
}

extern "C" void remove_temps_and_die(int sig) {
  remove_temps();
  std::signal(sig, SIG_DFL);
  raise(sig);
}

// Also at std::exit (which skips the destructors of the AtomicFiles on the stack).
void install_handlers() {
  static bool done = false;
  if (done) return;
  done = true;
  std::atexit(remove_temps);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = remove_temps_and_die;
    sigaction(sig, &sa, nullptr);
  }
}

std::string dir_of(const std::string &path) {
  size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string base_of(const std::string &path) {
  size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// Where a path points once its folder's links are resolved (the file itself may not exist yet).
std::string resolved(const std::string &path) {
  char buf[PATH_MAX];
  if (realpath(dir_of(path).c_str(), buf) == nullptr) return path;
  return std::string(buf) + "/" + base_of(path);
}

bool same_file(const std::string &a, const std::string &b) {
  if (resolved(a) == resolved(b)) return true;
  struct stat sa, sb;
  return stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

} // namespace

bool check_outputs(const std::vector<NamedPath> &outputs, const std::vector<NamedPath> &inputs, std::string *err) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath &o = outputs[i];
    if (o.path.empty()) {
      *err = o.flag + ": the file name is empty";
      return false;
    }
    for (const NamedPath &in : inputs)
      if (!in.path.empty() && same_file(o.path, in.path)) {
        *err = o.flag + " '" + o.path + "' is the input " + in.flag + " '" + in.path + "': it would be overwritten";
        return false;
      }
    for (size_t k = 0; k < i; ++k)
      if (same_file(o.path, outputs[k].path)) {
        *err = o.flag + " '" + o.path + "' is also " + outputs[k].flag + " '" + outputs[k].path +
               "': one would overwrite the other";
        return false;
      }
  }
  for (const NamedPath &o : outputs) {
    struct stat st;
    const std::string dir = dir_of(o.path);
    if (o.path.back() == '/' || (stat(o.path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))) {
      *err = "cannot write " + o.flag + " '" + o.path + "': it is a directory";
      return false;
    }
    const int found = stat(dir.c_str(), &st);
    if (found != 0 || !S_ISDIR(st.st_mode)) {
      *err = "cannot write " + o.flag + " '" + o.path + "': folder '" + dir + "': " +
             std::strerror(found != 0 ? errno : ENOTDIR);
      return false;
    }
    if (access(dir.c_str(), W_OK) != 0) {
      *err = "cannot write " + o.flag + " '" + o.path + "': folder '" + dir + "': " + std::strerror(errno);
      return false;
    }
  }
  return true;
}

std::string json_quote(const std::string &s) {
  std::string q = "\"";
  for (const char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      q += '\\';
      q += ch;
    } else if (c < 0x20 || c == 0x7F) {
      char u[8];
      std::snprintf(u, sizeof u, "\\u%04x", c);
      q += u;
    } else {
      q += ch;
    }
  }
  return q + "\"";
}

bool AtomicFile::open(const std::string &path, std::string *err) {
  discard();
  install_handlers();
  path_ = path;
  tmp_ = dir_of(path) + "/." + base_of(path) + ".XXXXXX";
  int fd = tmp_.size() < PATH_MAX ? mkstemp(tmp_.data()) : -1;
  if (fd < 0) {
    *err = "cannot write '" + path + "': " + std::strerror(tmp_.size() < PATH_MAX ? errno : ENAMETOOLONG);
    return false;
  }
  // mkstemp makes 0600; an output gets the permissions a plain fopen would give it.
  mode_t mask = umask(0);
  umask(mask);
  fchmod(fd, 0666 & ~mask);
  for (int i = 0; i < kMaxTemps && slot_ < 0; ++i)
    if (!g_used[i]) {
      std::memcpy(g_temps[i], tmp_.c_str(), tmp_.size() + 1);
      g_used[i] = 1;
      slot_ = i;
    }
  f_ = fdopen(fd, "w");
  return f_ != nullptr;
}

bool AtomicFile::commit(std::string *err) {
  if (f_ == nullptr) return false;
  bool ok = std::fflush(f_) == 0 && std::ferror(f_) == 0 && fsync(fileno(f_)) == 0;
  int e = errno;
  ok = std::fclose(f_) == 0 && ok;
  f_ = nullptr;
  if (ok && std::rename(tmp_.c_str(), path_.c_str()) == 0) {
    tmp_.clear();
    discard();
    int dfd = ::open(dir_of(path_).c_str(), O_RDONLY);
    if (dfd >= 0) {
      fsync(dfd);
      close(dfd);
    }
    return true;
  }
  *err = "error writing '" + path_ + "': " + std::strerror(ok ? errno : e) + " (the previous file, if any, is unchanged)";
  discard();
  return false;
}

void AtomicFile::discard() {
  if (f_ != nullptr) std::fclose(f_);
  f_ = nullptr;
  if (!tmp_.empty()) unlink(tmp_.c_str());
  tmp_.clear();
  if (slot_ >= 0) g_used[slot_] = 0;
  slot_ = -1;
}

void write_csv_header(std::FILE *f) {
  std::fprintf(f, "episode,seed,step,t_s,theta_rad,omega_rad_s,v_rotating,v_target,v_spill,v_flight,action,"
                  "torque_nm,torque_frac,reward\n");
}

void write_csv_episode(std::FILE *f, int episode, uint32_t seed, const std::vector<Sample> &samples, double tau_max) {
  for (const Sample &s : samples)
    std::fprintf(f, "%d,%u,%u,%.3f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d,%.4f,%.6f,%.6f\n", episode, seed, s.obs.step,
                 s.obs.t, s.obs.theta, s.obs.omega, s.obs.v_rotating, s.obs.v_target, s.obs.v_spill, s.obs.v_flight,
                 s.action, s.obs.torque, s.obs.torque / tau_max, s.reward);
}

void write_render_json(std::FILE *f, const poursim_config_t &config, const Recorder &rec, const std::string &title,
                       const poursim_episode_t &m) {
  const poursim_config_t *c = &config;
  const std::vector<float> &radius = rec.radius;
  const int n = static_cast<int>(radius.size());
  const double fps = rec.frame_every > 0 ? 1.0 / (rec.frame_every * c->dt) : 0.0;
  std::fprintf(f, "{\"fps\": %.3f, \"title\": %s, \"poured\": %.4f, \"spilled\": %.4f, \"finish_s\": %.3f,\n", fps,
               json_quote(title).c_str(), m.poured, m.spilled, m.finish_time);
  std::fprintf(f, "\"scene\": {\"inner_width\": %.5f, \"height\": %.5f, \"wall\": %.5f, \"pivot_x\": 0.0, "
                  "\"pivot_y\": %.5f, \"target_x\": %.5f, \"theta_max\": %.5f},\n",
               c->bucket_inner_width, c->bucket_height, c->bucket_wall, c->pivot_height, c->target_dx, c->theta_max);
  std::fprintf(f, "\"radius\": [");
  for (int i = 0; i < n; ++i) std::fprintf(f, "%s%.5f", i ? "," : "", static_cast<double>(radius[static_cast<size_t>(i)]));
  std::fprintf(f, "],\n\"series\": {\"t\": [");
  // Plots at 100 Hz are plenty.
  std::vector<const Sample *> pick;
  for (size_t i = 0; i < rec.samples.size(); i += 10) pick.push_back(&rec.samples[i]);
  const char *keys[] = {"t", "theta", "v_rotating", "v_target", "v_spill", "torque"};
  for (int k = 0; k < 6; ++k) {
    if (k > 0) std::fprintf(f, "], \"%s\": [", keys[k]);
    for (size_t i = 0; i < pick.size(); ++i) {
      const poursim_obs_t &o = pick[i]->obs;
      double v = k == 0 ? o.t : k == 1 ? o.theta : k == 2 ? o.v_rotating : k == 3 ? o.v_target : k == 4 ? o.v_spill : o.torque;
      std::fprintf(f, "%s%.5g", i ? "," : "", v);
    }
  }
  std::fprintf(f, "]},\n\"frames\": [");
  for (size_t k = 0; k < rec.frames.size(); ++k) {
    std::fprintf(f, "%s\n{\"t\": %.3f, \"theta\": %.5f, \"xy\": [", k ? "," : "", rec.frame_t[k], rec.frame_theta[k]);
    const std::vector<float> &xy = rec.frames[k];
    for (size_t i = 0; i < xy.size(); ++i) std::fprintf(f, "%s%.4f", i ? "," : "", static_cast<double>(xy[i]));
    std::fprintf(f, "]}");
  }
  std::fprintf(f, "]}\n");
}

bool save_render_json(const std::string &path, const poursim_config_t &config, const Recorder &rec,
                      const std::string &title, const poursim_episode_t &m, std::string *err) {
  AtomicFile out;
  if (!out.open(path, err)) return false;
  write_render_json(out.stream(), config, rec, title, m);
  return out.commit(err);
}

} // namespace poursim
