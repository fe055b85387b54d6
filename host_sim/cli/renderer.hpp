// SPDX-License-Identifier: MIT
// The programs host_sim --render runs: the renderer (pour-render, the tools' entry point) and ffmpeg for MP4.
#ifndef POURSIM_RENDERER_HPP
#define POURSIM_RENDERER_HPP

#include <string>

namespace poursim {

// The program a shell would run for name: name itself if it holds a '/', else the first executable of that
// name in a PATH folder (an empty entry is the current folder). Empty if there is none.
std::string find_program(const std::string &name);

// The renderer host_sim --render runs: $POUR_RENDER, else the tools' console entry point on PATH.
const char *renderer_name();

// Runs `renderer TRAJECTORY.json OUT` and waits for it; returns 0 if it exited 0, else says why on stderr
// and returns 1.
int run_render(const std::string &renderer, const std::string &json_path, const std::string &out);

} // namespace poursim

#endif // POURSIM_RENDERER_HPP
