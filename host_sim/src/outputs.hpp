// SPDX-License-Identifier: MIT
// host_sim's output files: checked before the run, written to a temporary beside the target and renamed
// over it only when complete, so a failed or interrupted run never leaves a partial file or destroys one.
#ifndef POURSIM_OUTPUTS_HPP
#define POURSIM_OUTPUTS_HPP

#include <cstdio>
#include <string>
#include <vector>

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

} // namespace poursim

#endif // POURSIM_OUTPUTS_HPP
