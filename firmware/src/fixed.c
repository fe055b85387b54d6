/* SPDX-License-Identifier: MIT */
#include "pour/fixed.h"

const char *pour_status_name(pour_status_t status) {
  switch (status) {
    case POUR_OK:
      return "POUR_OK";
    case POUR_EINVAL:
      return "POUR_EINVAL";
    case POUR_ESHAPE:
      return "POUR_ESHAPE";
    case POUR_EFORMAT:
      return "POUR_EFORMAT";
    case POUR_ECORRUPT:
      return "POUR_ECORRUPT";
    case POUR_ECALIBRATION:
      return "POUR_ECALIBRATION";
    case POUR_EBOOT:
      return "POUR_EBOOT";
    case POUR_EPARAMS:
      return "POUR_EPARAMS";
    case POUR_EALIGN:
      return "POUR_EALIGN";
  }
  return "POUR_E?";
}
