// SPDX-License-Identifier: BSD-3-Clause
/* The few HAL and RTAPI calls hexatwistkins.c makes at load time, standing in for LinuxCNC's so
 * that the benchmark can call the module's kinematics functions directly in one process: pins
 * get storage, messages go to stderr. Nothing here runs in the timed loops. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "hal.h"
#include "rtapi.h"

int hal_init(const char* name) {
  (void)name;
  return 1;
}
int hal_exit(int comp_id) {
  (void)comp_id;
  return 0;
}
int hal_ready(int comp_id) {
  (void)comp_id;
  return 0;
}
void* hal_malloc(long int size) { return calloc(1, (size_t)size); }

#define PIN(type, name)                                                                  \
  int name(hal_pin_dir_t dir, type** data_ptr_addr, int comp_id, const char* fmt, ...) { \
    (void)dir;                                                                           \
    (void)comp_id;                                                                       \
    (void)fmt;                                                                           \
    *data_ptr_addr = calloc(1, sizeof(type));                                            \
    return *data_ptr_addr ? 0 : -1;                                                      \
  }
PIN(hal_float_t, hal_pin_float_newf)
PIN(hal_s32_t, hal_pin_s32_newf)
PIN(hal_u32_t, hal_pin_u32_newf)
PIN(hal_bit_t, hal_pin_bit_newf)

void rtapi_print_msg(msg_level_t level, const char* fmt, ...) {
  va_list args;
  if (level > RTAPI_MSG_ERR) return;
  va_start(args, fmt);
  vfprintf(stderr, fmt, args);
  va_end(args);
}
