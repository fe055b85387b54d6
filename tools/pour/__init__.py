"""pour: offline tools for the soymilk-pouring controller.

    pour.paths, pour.atomic, pour.libpoursim, pour.records, pour.functions   shared: the build tree and the
                  package data, atomic writes, libpoursim.so opened once, the ctypes records built from its
                  layout table, its functions declared from its function table
    pour.core     the firmware core through ctypes: its config, envelope, estimator and control pipeline
    pour.cli      shared: every program's --version and its progress bars (tqdm, off with --quiet)
    pour.policy   the policy as the firmware runs it: float softmax-linear (linear), its bit-exact
                  fixed-point reference (fixedpoint), weights.h (weights_h), policy.json -> weights.h
                  (export), golden vectors (golden)
    pour.sim      the simulator: libpoursim's binding (poursim), the episode record (episode), the trainer's
                  episode sources (envs, adapter), the Gymnasium environment (gym_env) and the named rig
                  distributions of configs/sim (rigs)
    pour.train    the trainer: run config (settings, config), the training methods' registry (methods):
                  policy gradient (pg, its maths in reinforce) and random search (ars), the run directory
                  they share (rundir), pour-train (trainer), the executors training and evaluation run
                  episodes on (executors), the Ray benchmark (ray_bench)
    pour.eval     held-out evaluation and figures: evaluate, robustness, robust_scale, results, sweep,
                  plots, render
    pour.lcm      the LCM link's tools: channels, messages, sensors, cmd, run, spy, logfile, live_view
    pour.can      the CAN protocol's DBC (dbc) and bus load (bus_load)
    pour.bench    the bench over CAN: scan, state, commands, parameters, logs (node); pour-bench (cli)
    pour.examples other libraries training the firmware's policy class: Stable-Baselines3's PPO (sb3_ppo)
    pour.sysid    system identification: the experiment's log (log), the fit (fit), rig files (rig);
                  pour-sysid (cli)

A subpackage imports only those on its row (and the shared modules, which import no subpackage);
tests/python/test_imports.py checks it:

    pour.core      -
    pour.policy    core
    pour.sim       policy, core
    pour.train     sim, policy, sysid
    pour.eval      train, sim, policy, sysid
    pour.lcm       eval, sim
    pour.can       -
    pour.bench     can, policy
    pour.sysid     bench, sim
    pour.examples  train, sim, policy

So the simulator never reaches the trainer, and nothing but the evaluation (a sweep trains its trials;
results and robust_scale read training runs and use the trainer's Ray executors) and the examples (sb3_ppo
--like reads a training config and validates as the trainer does) imports pour.train.
"""
