// SPDX-License-Identifier: BSD-3-Clause
// Designing the seed's fixed U-joint axes (docs/theory/design.md §16-18): the constant-orientation
// workspace's volume with its stated error, the required workspace (the study's tests and 2000
// random combined poses), and the symmetric turns of the axes that minimise the largest twist over
// it, every limit kept and the volume within 5 %. The twin of examples/python/08_design.py, which
// also maps the twist over a slice before and after.
#include <hexatwist/hexatwist.hpp>

#include <cstdio>

int main() {
  using namespace hexatwist;
  const Config config = default_config();
  const Model& model = config.rig.model();

  WorkspaceVolume volume;
  if (workspace_volume(model, Vector3d::Zero(), VolumeOptions{}, volume) != Status::Ok) return 1;
  std::printf("workspace volume at home orientation: %.4f m^3 (stated error %.4f m^3)\n", volume.volume, volume.error);

  RequiredWorkspace required;
  if (required_workspace(model, config.study, RequiredWorkspaceSpec{}, Strategy::Compensated, required) != Status::Ok)
    return 1;
  AxisDesign design;
  if (const Status s = design_axes(model, required.poses, DesignOptions{}, design); s != Status::Ok) {
    std::printf("design_axes: %s\n", describe(s).data());
    return 1;
  }
  const DesignEvaluation &before = design.before, &after = design.after;
  std::printf("largest |twist| over the required workspace (%zu poses): %.2f deg (leg %d) -> %.2f deg (leg %d)\n",
              required.poses.size(), rad2deg(before.max_twist), before.twist_leg + 1, rad2deg(after.max_twist),
              after.twist_leg + 1);
  std::printf("volume %.4f -> %.4f m^3\n", before.volume, after.volume);
  std::printf("turns of ja, jd [deg]:");
  for (const double a : design.turns.base) std::printf(" %+.2f", rad2deg(a));
  std::printf(" |");
  for (const double a : design.turns.platform) std::printf(" %+.2f", rad2deg(a));
  std::printf("\n");
  return 0;
}
