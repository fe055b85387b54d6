// SPDX-License-Identifier: MIT
// host_sim's output files: checked before the run, written to a temporary beside the target and renamed
// over it only when complete, so a failed or interrupted run never leaves a partial file or destroys one;
// and what goes into them (the CSV of every step, the trajectory JSON for pour-render).
#ifndef POURSIM_OUTPUTS_HPP
#define POURSIM_OUTPUTS_HPP

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "episode_run.hpp"
#include "poursim/poursim.h"

namespace poursim {

// s as a JSON string literal, quotes included: a quote and a backslash escaped with a backslash, control
// characters as \u00XX, every other byte (UTF-8 included) as it is.
std::string json_quote(const std::string &s);

struct NamedPath {
  std::string flag; // the option it came from, for messages ("--csv", "--render (its .png)")
  std::string path;
};

// Before any work: every output a file name in an existing, writable folder, and no output naming an
// input or another output (by resolved path, and by inode where the file exists: links count as the
// same file). On failure returns false with the reason in *err.
bool check_outputs(const std::vector<NamedPath> &outputs, const std::vector<NamedPath> &inputs, std::string *err);

// One output, written atomically: open() creates ".<name>.XXXXXX" beside path; commit() flushes, syncs
// and renames it to path; discard() (and the destructor, and SIGINT/SIGTERM/SIGHUP) removes it.
class AtomicFile {
 public:
  AtomicFile() = default;
  AtomicFile(const AtomicFile &) = delete;
  AtomicFile &operator=(const AtomicFile &) = delete;
  ~AtomicFile() { discard(); }
  bool open(const std::string &path, std::string *err);
  std::FILE *stream() const { return f_; }
  bool commit(std::string *err);
  void discard();

 private:
  std::string path_, tmp_;
  std::FILE *f_ = nullptr;
  int slot_ = -1;
};

// The CSV of every step: the header line, then each episode's samples (its number from 1, its seed) as it
// ends. tau_max [N·m] turns the torque into the fraction of the torque_frac column.
void write_csv_header(std::FILE *f);
void write_csv_episode(std::FILE *f, int episode, uint32_t seed, const std::vector<Sample> &samples, double tau_max);

// The trajectory pour-render animates, as one JSON object: title (through json_quote), the episode's figures
// m, the scene of config, the circles' radii, every tenth sample's series and the frames of rec (recorded
// every rec.frame_every steps, which sets fps).
void write_render_json(std::FILE *f, const poursim_config_t &config, const Recorder &rec, const std::string &title,
                       const poursim_episode_t &m);
// The same, written to path as an AtomicFile. On failure returns false with the reason in *err.
bool save_render_json(const std::string &path, const poursim_config_t &config, const Recorder &rec,
                      const std::string &title, const poursim_episode_t &m, std::string *err);

} // namespace poursim

#endif // POURSIM_OUTPUTS_HPP
