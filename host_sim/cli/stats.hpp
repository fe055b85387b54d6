// SPDX-License-Identifier: MIT
// Summary statistics over episodes, for host_sim's summary and its bench.
#ifndef POURSIM_STATS_HPP
#define POURSIM_STATS_HPP

#include <vector>

namespace poursim {

// Arithmetic mean; 0 for an empty series.
double mean(const std::vector<double> &v);
// Sample standard deviation (n − 1 in the denominator); 0 for fewer than two values.
double stdev(const std::vector<double> &v);

} // namespace poursim

#endif // POURSIM_STATS_HPP
