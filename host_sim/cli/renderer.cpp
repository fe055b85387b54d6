// SPDX-License-Identifier: MIT
#include "renderer.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

extern char **environ;

namespace poursim {

std::string find_program(const std::string &name) {
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : "";
  const char *path = std::getenv("PATH");
  std::string dirs = path != nullptr ? path : "";
  for (size_t a = 0; a <= dirs.size();) {
    size_t b = dirs.find(':', a);
    if (b == std::string::npos) b = dirs.size();
    std::string file = (b > a ? dirs.substr(a, b - a) : ".") + "/" + name;
    if (access(file.c_str(), X_OK) == 0) return file;
    a = b + 1;
  }
  return "";
}

const char *renderer_name() {
  const char *env = std::getenv("POUR_RENDER");
  return env != nullptr && *env != '\0' ? env : "pour-render";
}

int run_render(const std::string &renderer, const std::string &json_path, const std::string &out) {
  std::vector<std::string> args = {renderer, json_path, out};
  std::vector<char *> argv;
  for (std::string &s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  pid_t pid;
  int err = posix_spawn(&pid, renderer.c_str(), nullptr, nullptr, argv.data(), environ);
  if (err != 0) {
    std::fprintf(stderr, "host_sim: cannot start the renderer %s: %s\n", renderer.c_str(), std::strerror(err));
    return 1;
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "host_sim: the renderer (%s) failed\n", renderer.c_str());
    return 1;
  }
  return 0;
}

} // namespace poursim
