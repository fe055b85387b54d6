/* SPDX-License-Identifier: MIT */
/* LCM transport for the controller: POUR_SENSORS and POUR_COMMAND in, POUR_TORQUE and POUR_STATUS out. */
#ifndef POUR_LINUX_IO_LCM_H
#define POUR_LINUX_IO_LCM_H

#include "io.h"

/* Opens LCM at url (NULL: POUR_LCM_DEFAULT_URL) and subscribes. Returns 0, or -1 with a message on stderr. */
int pour_io_lcm_open(pour_io_t *io, const char *url);

#endif /* POUR_LINUX_IO_LCM_H */
