/* SPDX-License-Identifier: MIT */
/* Fixed-point types, status codes and the saturating helpers every pour module shares. */
#ifndef POUR_FIXED_H
#define POUR_FIXED_H

#include <stdint.h>

/* Q1.15: [-1, 1 - 2^-15], one LSB = 2^-15. */
typedef int16_t q15_t;

#define POUR_Q15_ONE_INT 32768 /* 1.0 in Q15, as an int32 (not representable in q15_t) */
#define POUR_Q15_MAX INT16_MAX
#define POUR_Q15_MIN INT16_MIN

/* One status type for every fallible call: 0 is success, negative values are errors. */
typedef enum {
  POUR_OK = 0,
  POUR_EINVAL = -1,  /* a null pointer or an argument outside its documented range */
  POUR_ESHAPE = -2,  /* weights with an unsupported shape (features, actions) */
  POUR_EFORMAT = -3, /* weights with an unsupported Q format or format version */
  POUR_ECORRUPT = -4,    /* weights whose content hash does not match */
  POUR_ECALIBRATION = -5, /* no valid drive calibration (none stored, corrupt, an older format, out of range) */
  POUR_EBOOT = -6,        /* the option bytes would boot the ROM bootloader (B-G431B-ESC1: nSWBOOT0, nBOOT0) */
  POUR_EPARAMS = -7,      /* stored parameters corrupt, of another layout, out of range, or refused by the core */
  POUR_EALIGN = -8        /* a valid drive calibration is stored, but its electrical offset is not trusted in this
                           * power cycle (the motor encoder has no index; its count starts at 0 at every boot):
                           * RUN is refused until a CalibrationStart finds it again */
} pour_status_t;

/* Name of a status value, for logs and error messages. */
const char *pour_status_name(pour_status_t status);

/* Saturate an int32 to the q15_t range. */
static inline q15_t pour_sat_q15(int32_t x) {
  return (q15_t)(x > POUR_Q15_MAX ? POUR_Q15_MAX : (x < POUR_Q15_MIN ? POUR_Q15_MIN : x));
}

/* Saturate an int64 to the int32 range. */
static inline int32_t pour_sat_i32(int64_t x) {
  return (int32_t)(x > INT32_MAX ? INT32_MAX : (x < INT32_MIN ? INT32_MIN : x));
}

#endif /* POUR_FIXED_H */
