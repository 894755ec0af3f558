// SPDX-License-Identifier: BSD-3-Clause
// Options the design commands share (workspace, design, tolerance): the required workspace
// (--workspace SPEC or --trajectory FILE...) and the Dask scheduler (--scheduler tcp://HOST:PORT).
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "hexatwist/hexatwist.hpp"

namespace hexatwist::cli {

class JsonWriter;

/// Where the required workspace comes from.
struct RequiredOptions {
  std::string workspace;                  ///< SPEC: key=value,... (tests, samples, random, linear, angular, seed)
  std::vector<std::string> trajectories;  ///< CSV files (simulate's format): every row a required pose
};

/// Adds --workspace and --trajectory (mutually exclusive) to a command.
void add_required_options(CLI::App& app, RequiredOptions& o);

/// The spec of --workspace: "tests=on,samples=41,random=2000,linear=0.25,angular=15,seed=1" (linear in
/// m, angular in deg; every key optional, the defaults those). ExitError(2) naming the key otherwise.
RequiredWorkspaceSpec parse_workspace_spec(const std::string& text);

/// The required workspace of a command.
struct RequiredPoses {
  std::vector<Pose> poses;
  bool from_spec = true;        ///< false: from --trajectory files
  RequiredWorkspaceSpec spec;   ///< the spec (from_spec)
  RequiredWorkspace workspace;  ///< what required_workspace kept (from_spec)
  std::string description;      ///< for the report
};

/// The required poses for `config`: the spec's (poses the platform does not reach left out), or every
/// row of the trajectories (ExitError(3) naming file, line and limit for a row outside a limit,
/// ExitError(2) for a file that does not parse).
RequiredPoses required_poses(const Config& config, const RequiredOptions& o);

/// Writes the required workspace's description as a JSON object.
void write_required_json(JsonWriter& j, const RequiredPoses& r);

/// Adds --cell (the side of the volume's grid cell [m]; 0: the bounds' larger side / 64) to a
/// command that computes a workspace volume (workspace, design).
void add_cell_option(CLI::App& app, double& cell);
/// ExitError(2) naming --cell unless it is 0 (automatic) to 1 m.
void check_cell_option(double cell);

/// Adds --scheduler (a Dask scheduler's address, tcp://HOST:PORT) to a command.
void add_scheduler_option(CLI::App& app, std::string& scheduler);

/// "tests": the spec as the request JSON of a cluster job wants it (SI).
void write_spec_json(JsonWriter& j, const RequiredWorkspaceSpec& s);

/// Limits in the five groups the figures colour them by: 0 shortest leg, 1 longest leg, 2 U-joint
/// bend, 3 U-joint singularity, 4 platform singularity; -1 for a status that is none of them.
int limit_group(Status s);
/// The groups' names, as the legends show them.
extern const char* const kLimitGroups[5];

}  // namespace hexatwist::cli
