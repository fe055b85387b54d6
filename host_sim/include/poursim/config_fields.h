/* SPDX-License-Identifier: MIT */
/* The simulator's configuration, declared once: every key with its type, default, range, unit and meaning.
 * This list makes poursim_config_t (poursim.h), the field table, the defaults and the range checks
 * (config.cpp), poursim_config_describe (--help), Python's view of the config (pour.sim.poursim asks the
 * library) and configs/sim/default.cfg (generated: `cmake --build --preset host --target default_cfg`).
 *
 * X(kind, name, default, min, max, unit, doc): kind DOUBLE, INT or U32; min and max inclusive.
 * S(title): a section heading of default.cfg; nothing else.
 * Adding a key is one X line here (docs/simulator.md, "Configuration"); ranges are wide enough for
 * experiments and narrow enough that the physics stays meaningful. */
#ifndef POURSIM_CONFIG_FIELDS_H
#define POURSIM_CONFIG_FIELDS_H

#define POURSIM_CONFIG_FIELDS(X, S) \
  S("time") \
  X(DOUBLE, dt, 0.001, 1e-4, 0.01, "s", "physics step = the 1 kHz control tick") \
  X(INT, substeps, 1, 1, 16, "-", "Box2D sub-steps per step (1 keeps circle-wall contacts within 0.3 mm)") \
  X(DOUBLE, episode_s, 10.0, 0.01, 600.0, "s", "episode length") \
  X(DOUBLE, settle_s, 0.6, 0.0, 10.0, "s", "the liquid settles this long, bucket held upright, before t = 0") \
  S("geometry: both buckets are the same U of three boxes") \
  X(DOUBLE, bucket_inner_width, 0.24, 0.05, 1.0, "m", "inner width (24 cm diameter)") \
  X(DOUBLE, bucket_height, 0.33, 0.05, 1.0, "m", "outer height") \
  X(DOUBLE, bucket_wall, 0.005, 0.001, 0.05, "m", "wall and bottom thickness") \
  X(DOUBLE, pivot_height, 0.56, 0.1, 5.0, "m", "the rotating bucket's centre (pivot) above the ground") \
  X(DOUBLE, target_dx, 0.28, -2.0, 2.0, "m", "target's centre x minus pivot x (> 0: the pouring side; under a slow pour's stream)") \
  S("masses") \
  X(DOUBLE, bucket_mass, 2.0, 0.01, 100.0, "kg", "the rotating bucket (steel)") \
  S("liquid: n_particles circles share the fill's cross-section, spacing s = sqrt(width*fill_depth/n)") \
  X(DOUBLE, fill_depth, 0.221, 0.01, 1.0, "m", "depth at rest in the upright bucket (10 L in a round bucket of 24 cm)") \
  X(DOUBLE, liquid_density, 1030.0, 500.0, 2000.0, "kg/m^3", "soymilk; mass = density*fill_depth*pi*(width/2)^2") \
  X(INT, n_particles, 150, 2, POURSIM_MAX_PARTICLES, "-", "circles") \
  X(INT, fluid, 1, 0, 1, "0/1", "1: particle fluid (pressure, viscosity); 0: rigid circle pile") \
  X(DOUBLE, fluid_smoothing, 1.8, 1.2, 3.0, "-", "interaction radius h / spacing s") \
  X(DOUBLE, fluid_contact_radius, 0.5, 0.1, 0.5, "-", "Box2D circle radius / spacing s (contacts with the buckets)") \
  X(DOUBLE, fluid_stiffness, 10000.0, 10.0, 1e5, "m/s^2", "pressure stiffness k") \
  X(DOUBLE, fluid_viscosity, 5.0, 0.0, 1e3, "1/s", "pair viscosity sigma") \
  X(DOUBLE, fluid_agitation, 0.6, 0.0, 5.0, "m/s", "thermal speed v_T of the pairs: keeps 150 particles liquid") \
  S("contact model") \
  X(DOUBLE, restitution_liquid, 0.5, 0.0, 1.0, "-", "circle-circle, the pile only (fluid = 0)") \
  X(DOUBLE, restitution_wall, 0.1, 0.0, 1.0, "-", "circle-wall (pairs are mixed with min, so it wins)") \
  X(DOUBLE, friction, 0.03, 0.0, 2.0, "-", "low: the pile levels closer to a liquid (onset 60 deg vs 65 at 0.1)") \
  X(DOUBLE, restitution_threshold, 1.0, 0.0, 100.0, "m/s", "collisions slower than this do not bounce") \
  X(DOUBLE, contact_hertz, 240.0, 1.0, 10000.0, "Hz", "contact stiffness") \
  S("actuation (host_sim --policy takes tau_max from the policy's weights.h)") \
  X(DOUBLE, tau_max, 20.0, 0.01, 1000.0, "N m", "torque of action level 1.0") \
  X(DOUBLE, theta_min, -0.0872664626, -1.0, 0.0, "rad", "lower hard stop (-5 deg)") \
  X(DOUBLE, theta_max, 2.35619449, 0.1, 3.1, "rad", "upper hard stop (135 deg)") \
  X(DOUBLE, brake_torque, 40.0, 0.0, 1000.0, "N m", "holding brake's rating (poursim_set_brake): twice the drive's peak") \
  S("the drive: a 48 V BLDC of the 57 mm class on a 1:20 planetary gearhead (docs/simulator.md, \"The rig\")") \
  X(DOUBLE, motor_peak_torque, 25.0, 0.1, 1000.0, "N m at the output", "the command is clamped to it (1.35 N m x 20 x 0.93)") \
  X(DOUBLE, motor_no_load_speed, 21.0, 0.1, 1000.0, "rad/s at the output", "motoring torque reaches 0 here (4,000 rpm / 20)") \
  X(DOUBLE, motor_rotor_inertia, 2.4e-5, 0.0, 0.1, "kg m^2 at the motor", "J*N^2 is added to the bucket's") \
  X(DOUBLE, gear_ratio, 20.0, 1.0, 1000.0, "-", "motor turns per output turn") \
  X(DOUBLE, friction_coulomb, 0.6, 0.0, 100.0, "N m", "Coulomb friction at the output, holds at standstill") \
  X(DOUBLE, friction_viscous, 0.02, 0.0, 100.0, "N m s/rad", "viscous friction at the output") \
  X(INT, command_latency_ticks, 1, 1, 100, "steps", "a command acts this many steps after the step it is given in") \
  X(DOUBLE, torque_scale, 1.0, 0.5, 2.0, "-", "the drive delivers this times the command (a torque constant off its datasheet)") \
  S("the full drive (docs/motor.md): the firmware's current loop around a motor, inverter and bus model") \
  X(INT, drive, 0, 0, 1, "-", "0: the torque-speed line above (the fast default for training); 1: field-oriented control at 20 kHz") \
  X(INT, drive_regen, 1, 0, 1, "-", "1: the drive's flux braking on; 0: off (regeneration charges the bus)") \
  X(INT, drive_fault, 0, 0, 5, "-", "injected: 0 none, 1 phase open, 2 phases shorted, 3 encoder reversed, 4 a current amplifier's offset broken, 5 motor encoder unplugged") \
  X(DOUBLE, supply_voltage, 24.0, 12.0, 26.0, "V", "bench supply of the drive's bus (it cannot sink current)") \
  X(DOUBLE, bus_capacitance, 200e-6, 1e-5, 0.1, "F", "the drive's bus capacitance") \
  S("the rig's sensors (poursim_obs_t.encoder, scale_rotating_g, scale_target_g)") \
  X(INT, encoder_bits, 17, 8, 24, "bits", "single-turn absolute encoder on the output shaft") \
  X(DOUBLE, scale_rate_hz, 80.0, 1.0, 10000.0, "Hz", "load cells' conversion rate (HX711 at RATE high); held between") \
  X(DOUBLE, scale_delay_s, 0.05, 0.0, 1.0, "s", "a conversion reports the mean load over this span before it") \
  X(DOUBLE, scale_noise_g, 0.5, 0.0, 1000.0, "g", "Gaussian noise of a conversion, standard deviation") \
  X(DOUBLE, scale_resolution_g, 1.0, 1.0, 1000.0, "g", "readings are multiples of this") \
  S("what the firmware's rig file tells its envelope (docs/safety.md: Fill schedule)") \
  X(DOUBLE, fill_schedule_l, 0.0, 0.0, 100.0, "L", "a fill above this gets the knee of its onset angle less 3 deg (0: no schedule)") \
  S("domain randomisation: uniform +- around the nominal, drawn from the reset seed; 0 = off") \
  X(DOUBLE, rand_fill, 0.0, 0.0, 0.5, "relative", "fill_depth") \
  X(DOUBLE, rand_target_dx, 0.0, 0.0, 0.1, "m", "target_dx") \
  X(DOUBLE, rand_pivot_height, 0.0, 0.0, 0.1, "m", "pivot_height") \
  X(DOUBLE, rand_motor, 0.0, 0.0, 0.5, "relative", "peak torque, no-load speed, both frictions, rotor inertia") \
  X(DOUBLE, rand_bucket_mass, 0.0, 0.0, 0.5, "relative", "bucket_mass") \
  X(DOUBLE, rand_liquid, 0.0, 0.0, 0.5, "relative", "fluid viscosity, stiffness, agitation, liquid density") \
  X(DOUBLE, rand_sensor, 0.0, 0.0, 0.9, "relative", "scale delay and noise; latency +0 or +1 tick") \
  S("randomness") \
  X(U32, seed, 1, 0, 4294967295.0, "-", "default seed of reset() and the CLI")

#define POURSIM_CONFIG_CTYPE_DOUBLE double
#define POURSIM_CONFIG_CTYPE_INT int
#define POURSIM_CONFIG_CTYPE_U32 uint32_t

#endif /* POURSIM_CONFIG_FIELDS_H */
