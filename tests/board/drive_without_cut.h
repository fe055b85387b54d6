/* SPDX-License-Identifier: MIT */
/* hal_drive's hardware overcurrent cut and interrupt mask for the benches whose motor follows the currents
 * ideally (the QEMU smoke image, the host's calibration run; each file that includes it gets its own copy):
 * the comparators arm and never trip, and no real interrupt preempts the loop, so the mask does nothing. */
#ifndef POUR_DRIVE_WITHOUT_CUT_H
#define POUR_DRIVE_WITHOUT_CUT_H

#include "hal_drive.h"

pour_status_t pour_hal_drive_arm_overcurrent(const uint16_t offset_counts[3]) {
  (void)offset_counts;
  return POUR_OK;
}
bool pour_hal_drive_overcurrent_tripped(void) { return false; }
void pour_hal_drive_clear_overcurrent(void) {}
void pour_hal_drive_mask(bool masked) { (void)masked; }

#endif /* POUR_DRIVE_WITHOUT_CUT_H */
