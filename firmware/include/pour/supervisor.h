/* SPDX-License-Identifier: MIT */
/* The supervisor beside the envelope: checks each fresh state against what the axis can physically do and
 * names the fault when it cannot be (runaway, overspeed, a wrong motor or encoder sign, a frozen encoder,
 * an impossible volume jump, a sender that repeats itself). Pure, fixed point, no I/O. The control step
 * latches what it reports and chooses the stop (docs/safety.md). */
#ifndef POUR_SUPERVISOR_H
#define POUR_SUPERVISOR_H

#include <stdbool.h>
#include <stdint.h>

#include "pour/faults.h"
#include "pour/fixed.h"
#include "pour/obs.h"

#define POUR_SUPERVISOR_WINDOW_MAX 10u /* longest plausibility window [ticks]: one decision period */

/* Checks that can be armed (pour_supervisor_config_t.checks); the default arms all of them. */
#define POUR_CHECK_POSITION 0x01u
#define POUR_CHECK_OVERSPEED 0x02u
#define POUR_CHECK_TORQUE_SIGN 0x04u
#define POUR_CHECK_ENCODER 0x08u
#define POUR_CHECK_VOLUME 0x10u
#define POUR_CHECK_SEQ 0x20u
#define POUR_CHECK_SCALE 0x40u
#define POUR_CHECK_ALL 0x7Fu

/* docs/safety.md gives the reason for every default. */
typedef struct {
  uint8_t checks;                /* POUR_CHECK_* armed */
  int32_t theta_margin_urad;     /* POSITION outside [θmin - margin, θmax + margin] of the envelope [µrad], > 0 */
  int32_t omega_max_urad_s;      /* OVERSPEED above this |θ̇| [µrad/s], > 0 */
  uint8_t window_ms;             /* plausibility window W [ticks], 2 .. POUR_SUPERVISOR_WINDOW_MAX */
  q15_t torque_min;              /* a mean |torque| over W at least this is beyond what gravity can resist, Q15 */
  int32_t omega_against_urad_s;  /* TORQUE_SIGN: moving against that torque faster than this [µrad/s], > 0 */
  uint8_t against_ms;            /* ... and speeding up that way, this many ticks in a row [ticks], >= 1 */
  int32_t encoder_move_urad;     /* ENCODER: under at least that torque, one way, θ leaves ±this [µrad], > 0 ... */
  uint8_t encoder_ms;            /* ... within this many ticks [ticks], >= 1 */
  q15_t volume_step_max;         /* VOLUME: no volume changes by more than this per tick since the reading
                                  * last changed (at most 16 ticks credited), Q15, > 0 */
  int32_t accel_full_urad_s2;    /* SCALE: θ̇'s path over W (Σ|Δθ̇|) beyond what full torque gives the lightest
                                  * load, at most this [µrad/s²] per unit of mean |τ| ... */
  int32_t accel_passive_urad_s2; /* ... and gravity and the liquid add at most this [µrad/s²], > 0 */
} pour_supervisor_config_t;

typedef struct {
  pour_supervisor_config_t config;
  int32_t theta_low_urad;        /* POSITION below this: the envelope's θmin - margin [µrad] */
  int32_t theta_high_urad;       /* ... or above this: θmax + margin [µrad] */
  q15_t torque[POUR_SUPERVISOR_WINDOW_MAX];  /* commanded torque of the last W ticks (ring), Q15 */
  int32_t omega[POUR_SUPERVISOR_WINDOW_MAX]; /* θ̇ seen at those ticks (ring) */
  uint16_t dw[POUR_SUPERVISOR_WINDOW_MAX];   /* |θ̇ change| into each from the tick before [32 µrad/s] */
  uint8_t head;                  /* next ring slot */
  uint8_t filled;                /* ring entries in use, up to W */
  int32_t sum;                   /* Σ torque over the ring, Q15 (kept as entries come and go: O(1) a tick) */
  int32_t sum_abs;               /* Σ |torque| */
  int32_t sum_dw;                /* Σ dw: the path of θ̇ over the ring [µrad/s] */
  int64_t passive_term;          /* accel_passive * W * 32768 [µrad/s² · ticks · Q15], fixed at init */
  uint8_t against;               /* consecutive ticks moving and speeding up against the torque */
  uint8_t over;                  /* consecutive ticks accelerating beyond what the command explains */
  int32_t still_theta_urad;      /* θ where the encoder was last seen to move [µrad] */
  uint16_t still_ticks;          /* fresh samples since, θ within ±encoder_move of it */
  uint16_t push_ticks;           /* consecutive ticks commanding >= torque_min one way ... */
  int8_t push_dir;               /* ... which way: +1, -1, or 0 (below torque_min) */
  bool have_state;               /* a state was judged since the restart */
  uint32_t last_seq;             /* seq of the last accepted sample */
  q15_t volume[3];               /* V_rot, V_tgt, V_spill when the volume reading last changed, Q15 */
  uint32_t ticks_since_volume;   /* ticks since then [ticks] */
  uint32_t seq_repeats;          /* fresh states refused since the last accepted one (seq did not advance) */
} pour_supervisor_t;

/* Defaults for the bench rig and the shipped policy (docs/safety.md). */
pour_supervisor_config_t pour_supervisor_default_config(void);

/* Validates config (POUR_EINVAL otherwise); theta_min/max_urad: the envelope's angle limits. */
pour_status_t pour_supervisor_init(pour_supervisor_t *sup, const pour_supervisor_config_t *config,
                                   int32_t theta_min_urad, int32_t theta_max_urad);

/* Forgets the history (a new run): the next state is accepted whatever its seq. */
void pour_supervisor_restart(pour_supervisor_t *sup);

/* Whether a fresh sample's seq continues the sample count: it must advance by 1 .. 32767 (mod 2^32) over the
 * last accepted one. A sample that does not is to be treated as not fresh (a frozen or replaying sender);
 * it is counted in seq_repeats, and the caller reports POUR_FAULT_SEQ when the input then times out. */
bool pour_supervisor_accept(pour_supervisor_t *sup, uint32_t seq);

/* One tick, before the command: state is the latest accepted state (fresh: it arrived this tick), judged
 * against the commands of the last W ticks. Returns the POUR_FAULT_* bits it proves (0: plausible). */
uint16_t pour_supervisor_step(pour_supervisor_t *sup, const pour_state_t *state, bool fresh);

/* After the command: records this tick's torque (Q15) with the state it answered. */
void pour_supervisor_record(pour_supervisor_t *sup, const pour_state_t *state, q15_t torque);

#endif /* POUR_SUPERVISOR_H */
