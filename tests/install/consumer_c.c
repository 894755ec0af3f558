// SPDX-License-Identifier: BSD-3-Clause
/* Uses the installed C API from C: compensated commands for a pose, then twist-aware forward
 * kinematics must return that pose. Exit code 0 only if it does. */
#include <hexatwist/c/hexatwist.h>

#include <math.h>
#include <stdio.h>

int main(void) {
  char error[256];
  hexatwist_model* model = hexatwist_model_default(error, sizeof error);
  if (!model) return 1;
  const double pose[6] = {0.05, -0.02, 0.1, 0.0, 0.0, 0.35};
  double command[6];
  hexatwist_fk_result fk;
  int code = 0;
  if (hexatwist_motor_commands(model, pose, HEXATWIST_COMPENSATED, command, NULL) != HEXATWIST_OK) code = 2;
  if (!code && hexatwist_forward_kinematics(model, command, HEXATWIST_MOTOR, NULL, NULL, &fk) != HEXATWIST_OK) code = 3;
  double err = 0.0;
  for (int k = 0; k < 6 && !code; ++k) err = fmax(err, fabs(fk.pose[k] - pose[k]));
  printf("C round trip error %.3g\n", err);
  hexatwist_model_free(model);
  return code ? code : err < 1e-9 ? 0 : 4;
}
