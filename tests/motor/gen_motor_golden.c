/* SPDX-License-Identifier: MIT */
/* Writes tests/golden/motor_golden.h: what the drive's current loop outputs, period by period, through the
 * scripted run of drive_script.h, recorded on the host. test_drive_golden replays the script on the host and
 * the emulated Cortex-M4 and must reproduce every compare, current and flag; the ctest
 * motor_golden_is_current checks the committed file is what this writes. usage: gen_motor_golden OUT.h */
#include <stdio.h>

#include "drive_script.h"

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: gen_motor_golden OUT.h\n");
    return 2;
  }
  static pour_drive_golden_t g[POUR_DRIVE_SCRIPT_PERIODS];
  if (pour_drive_script_run(g) != 0) {
    fprintf(stderr, "gen_motor_golden: the drive did not start\n");
    return 1;
  }
  FILE *f = fopen(argv[1], "w");
  if (f == NULL) {
    perror(argv[1]);
    return 1;
  }
  fprintf(f, "/* motor_golden.h: pour_drive_isr's outputs over the script of tests/motor/drive_script.h (%u periods),\n"
             " * recorded on the host by tests/motor/gen_motor_golden.c. DO NOT EDIT.\n"
             " * Row: compare[3], id, iq, limits, faults. */\n"
             "#ifndef POUR_MOTOR_GOLDEN_H\n#define POUR_MOTOR_GOLDEN_H\n\n#include \"drive_script.h\"\n\n"
             "static const pour_drive_golden_t pour_motor_golden[POUR_DRIVE_SCRIPT_PERIODS] = {\n",
          (unsigned)POUR_DRIVE_SCRIPT_PERIODS);
  for (unsigned k = 0; k < POUR_DRIVE_SCRIPT_PERIODS; ++k)
    fprintf(f, "    {{%u, %u, %u}, %d, %d, 0x%02x, 0x%04x},\n", g[k].compare[0], g[k].compare[1], g[k].compare[2],
            g[k].id, g[k].iq, g[k].limits, g[k].faults);
  fprintf(f, "};\n\n#endif /* POUR_MOTOR_GOLDEN_H */\n");
  return fclose(f) == 0 ? 0 : 1;
}
