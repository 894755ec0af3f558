// SPDX-License-Identifier: BSD-3-Clause
// The command line's door to a Dask cluster (`--scheduler tcp://HOST:PORT`): a request runs through the
// Python package (python3 -m hexatwist.cluster, which drives the workers), and the merged summaries
// come back as arrays for the command to finish its report with the library.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace hexatwist::cli {

/// The arrays a cluster job returns, by name (floats exact; integer counts as doubles, exact below 2^53).
using ClusterArrays = std::map<std::string, std::vector<double>>;

/// Runs `request` (JSON with job, scheduler and the job's settings) with the Python interpreter named
/// by HEXATWIST_PYTHON (else the one the package was built for, else python3 on PATH) and returns
/// what it printed. ExitError(2) when Python or the hexatwist package cannot be run or the scheduler
/// cannot be reached (naming --scheduler), ExitError(3) when the job fails (with Python's last line).
ClusterArrays run_cluster_job(const std::string& scheduler, const std::string& request);

/// The array `name` of `arrays` with exactly `size` values (size 0: any); ExitError(3) otherwise.
const std::vector<double>& cluster_array(const ClusterArrays& arrays, const std::string& name, std::size_t size = 0);

}  // namespace hexatwist::cli
