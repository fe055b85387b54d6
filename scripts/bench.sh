#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Benchmarks: measure and print; never fail on the figures (only on a build that does not work).
#   scripts/bench.sh              all sections but fuzz
#   scripts/bench.sh core         only the named sections (see SECTIONS below)
#   scripts/bench.sh fuzz 60      the fuzz targets, 60 s each (default 300)
#   scripts/bench.sh suite        ./scripts/test.sh's wall time by preset (build, tests), warm or cold as found
#   scripts/bench.sh suite-all    the same for ./scripts/test.sh --all
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
. scripts/lib/cli.sh
pour_script_cli "$ROOT/scripts/$(basename "$0")" "$@"

# --- section: core — the firmware core on an emulated Cortex-M4 -----------------------------------
# Instructions per control step under qemu-system-arm -icount shift=0 (one instruction per virtual ns,
# so the guest's SysTick turns into an instruction count: deterministic), for the hand-made 11-action
# and 2-action policies; flash and RAM of the core and of the STM32G431 image (arm-none-eabi-size).
# Bars: <= 1,000 instructions on the worst tick of the shipped schedule (the decision tick: a greedy policy
# computes no softmax; ctest mcu_bench_control_worst_tick holds it); core <= 4 KB flash and <= 512 B RAM;
# the image <= 32 KB flash and <= 8 KB static RAM with no soft-float helper. The same step on the flashed
# image, on the virtual board: the vboard section.
bench_core() {
  local build=build/cortex-m4 log
  log=$(mktemp)
  echo "== core: Cortex-M4 (STM32G431 image; QEMU mps2-an386, -icount shift=0) =="
  if ! { cmake --preset cortex-m4 && cmake --build --preset cortex-m4 -j2; } >"$log" 2>&1; then
    cat "$log"
    rm -f "$log"
    echo "error: the cortex-m4 build failed" >&2
    return 1
  fi
  rm -f "$log"
  local port=$build/firmware/ports/cortex-m4 n elf out
  for n in 11 2; do
    elf=$port/pour_bench_control_$n.elf
    echo "-- policy with $n actions:"
    if ! out=$(timeout 120 qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none \
                 -semihosting-config enable=on,target=native -icount shift=0 -kernel "$elf" 2>&1); then
      echo "$out"
      echo "error: $elf did not run to completion under QEMU" >&2
      return 1
    fi
    echo "$out" | sed 's/^/   /'
    if [ "$n" = 11 ]; then
      worst=$(sed -nE 's/.*worst tick: *([0-9]+) instructions.*/\1/p' <<<"$out")
      knee=$(sed -nE 's/.*worst tick, knee: *([0-9]+) instructions.*/\1/p' <<<"$out")
      every=$(sed -nE 's/.*decision every tick: *([0-9]+) instructions.*/\1/p' <<<"$out")
      avg=$(sed -nE 's/.*average: *([0-9]+) instructions.*/\1/p' <<<"$out")
      state=$(sed -nE 's/.*sizeof\(pour_control_t\) = ([0-9]+) B.*/\1/p' <<<"$out")
    fi
  done

  echo "-- sizes (arm-none-eabi-size, MinSizeRel):"
  local objdir=$build/firmware/CMakeFiles/pour_core.dir/src core_text=0 core_ram=0 all_text=0 o t d b
  for o in "$objdir"/*.obj; do
    read -r t d b < <(arm-none-eabi-size "$o" | awk 'NR == 2 {print $1, $2, $3}')
    all_text=$((all_text + t + d))
    case "$(basename "$o")" in
      fixed.c.obj|obs.c.obj|policy.c.obj|safety.c.obj|sensors.c.obj|supervisor.c.obj|control.c.obj)
        core_text=$((core_text + t + d)); core_ram=$((core_ram + d + b))
        printf '   %-18s %5d B flash\n' "$(basename "$o" .c.obj).c" $((t + d)) ;;
    esac
  done
  printf '   control core (fixed, obs, policy, safety, sensors, supervisor, control): %d B flash, %d B static RAM;\n' \
    "$core_text" "$core_ram"
  printf '   one controller instance (pour_control_t): %s B RAM\n' "${state:-?}"
  # Deepest stack of one step: the deepest chain of frames from pour_control_step in the benchmark image, from
  # the call graph its link-time optimisation writes (-fcallgraph-info=su; scripts/lib/stack_depth.py).
  local chain
  chain=$(python3 scripts/lib/stack_depth.py "$port"/pour_bench_control_11.elf.ltrans*.ci --root pour_control_step) || chain=""
  stack=$(cut -d' ' -f2 <<<"$chain")
  printf '   deepest stack of a control step: %s B (%s)\n' "${stack:-?}" "$(cut -d' ' -f3- <<<"$chain")"
  printf '   whole pour_core library: %d B flash\n' "$all_text"
  read -r t d b < <(arm-none-eabi-size "$port/pour_firmware.elf" | awk 'NR == 2 {print $1, $2, $3}')
  printf '   image pour_firmware.elf: %d B flash (text+data), %d B RAM (data+bss) + 2048 B stack reserve\n' \
    $((t + d)) $((d + b))
  local image_flash=$((t + d)) image_ram=$((d + b)) drive_flash=0 drive_ram=0 softfloat
  # The B-G431B-ESC1's drivers, each object (the image links them all since the current loop's interrupt is
  # wired; the sum of the motor drivers' objects on top of the image is kept as an upper bound).
  for o in $(find "$port"/CMakeFiles/pour_firmware.dir -name '*.obj' | sort); do # board/, drivers/, ../common/
    case "$(basename "$o")" in
      main.c.obj|startup.c.obj|hal_timer.c.obj|hal_motor.c.obj) continue ;;
    esac
    read -r t d b < <(arm-none-eabi-size "$o" | awk 'NR == 2 {print $1, $2, $3}')
    printf '   %-22s %5d B flash, %4d B static RAM\n' "$(basename "$o" .obj)" $((t + d)) $((d + b))
    case "$(basename "$o")" in
      pwm_tim1.c.obj|adc_inj.c.obj|opamp.c.obj|ocp.c.obj|encoder_tim4.c.obj|protect.c.obj|board_guard.c.obj)
        drive_flash=$((drive_flash + t + d)); drive_ram=$((drive_ram + d + b)) ;;
    esac
  done
  # The linked image's symbol table: what runs (the build's check reads the same, check_no_float.cmake).
  softfloat=$(arm-none-eabi-readelf -sW "$port/pour_firmware.elf" | grep -cE ' __aeabi_(f|d|[ui]2[fd]|[fd]2)|__(add|sub|mul|div)[sd]f3' || true)

  echo "-- against the bars:"
  verdict() { if [ "$1" -le "$2" ]; then echo "within"; else echo "OVER"; fi; }
  printf '   instructions/step, worst tick of the shipped schedule (11 actions, supervisor included): %s (bar 1000: %s)\n' \
    "$worst" "$(verdict "$worst" 1000)"
  printf '   the same with a fill schedule'"'"'s knee (a rig file'"'"'s; the default has none): %s (the envelope'"'"'s square root)\n' "${knee:-?}"
  printf '   instructions/step with a decision on every tick (no tick after it for the probabilities): %s\n' "$every"
  printf '   instructions/step, average (decision every 10 ms, 11 actions): %s\n' "$avg"
  printf '   core flash: %d B (bar 4096: %s); core RAM: %d B static + %s B per controller (bar 512: %s);\n' \
    "$core_text" "$(verdict "$core_text" 4096)" "$core_ram" "${state:-?}" \
    "$(verdict $((core_ram + ${state:-0})) 512)"
  printf '   with the deepest stack of a step: %d B\n' $((core_ram + ${state:-0} + ${stack:-0}))
  printf '   STM32G431 image: %d B flash (bar 32768: %s), %d B static RAM (bar 8192: %s); with every motor driver and the protection linked at most %d B flash, %d B static RAM\n' \
    "$image_flash" "$(verdict "$image_flash" 32768)" "$image_ram" "$(verdict "$image_ram" 8192)" \
    $((image_flash + drive_flash)) $((image_ram + drive_ram))
  printf '   soft-float helpers in the image (arm-none-eabi-readelf -s): %d (bar 0)\n' "$softfloat"
}

# --- section: motor — the drive's current loop on the emulated Cortex-M4, and the full drive in the simulator
# Instructions per current-loop interrupt (pour_drive_isr, each call timed on its own; SysTick resolution
# 40 instructions) and per drive tick under -icount shift=0; the worst-case stack of the interrupt over the
# thread from the image's call graph; then bench_motor's figures (docs/motor.md).
# Bars: interrupt <= 850 instructions worst; interrupt + 1 kHz step <= 1024 B of stack.
bench_motor() {
  local build=build/cortex-m4 log out
  log=$(mktemp)
  echo "== motor: the current loop on a Cortex-M4 (QEMU mps2-an386, -icount shift=0) =="
  if ! { cmake --preset cortex-m4 && cmake --build --preset cortex-m4 -j2 --target pour_bench_drive pour_bench_board_isr pour_bench_control_11 pour_firmware; } >"$log" 2>&1; then
    cat "$log"; rm -f "$log"; echo "error: the cortex-m4 build failed" >&2; return 1
  fi
  rm -f "$log"
  if ! out=$(timeout 120 qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none \
               -semihosting-config enable=on,target=native -icount shift=0 \
               -kernel "$build/firmware/ports/cortex-m4/pour_bench_drive.elf" 2>&1); then
    echo "$out"; echo "error: pour_bench_drive did not run to completion under QEMU" >&2; return 1
  fi
  echo "$out" | sed 's/^/   /'
  local worst board_out board_worst
  worst=$(sed -nE 's/.*pour_drive_isr\): worst ([0-9]+) instructions.*/\1/p' <<<"$out")
  # The same interrupt as the board runs it: the HAL's sample and compares around pour_drive_isr.
  if ! board_out=$(timeout 120 qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none \
               -semihosting-config enable=on,target=native -icount shift=0 \
               -kernel "$build/firmware/ports/cortex-m4/pour_bench_board_isr.elf" 2>&1); then
    echo "$board_out"; echo "error: pour_bench_board_isr did not run to completion under QEMU" >&2; return 1
  fi
  echo "$board_out" | sed 's/^/   /'
  board_worst=$(sed -nE 's/.*compares\): worst ([0-9]+) instructions.*/\1/p' <<<"$board_out")
  # Stack, from the call graph of the image's link (-fcallgraph-info=su under LTO; scripts/lib/stack_depth.py,
  # libgcc's and newlib's helpers counted from their disassembly). An exception pushes 8 words (no FPU) and up
  # to one more to align the stack to 8 B (CCR.STKALIGN): 36 B. The thread is the reset handler's deepest chain
  # (main inlined into it; its start-up, controller_init and drive_init, and its loop, run, are frames of
  # their own): the start-up enables the drive's interrupt (pour_board_drive_init, last), so the interrupt
  # counts over the start-up as over the loop. SysTick (pour_hal_timer_isr) and the ADC's interrupt keep the
  # priority 0 they reset to, so neither preempts the other; a fault (HardFault, NMI: negative priority)
  # may nest on either, and is printed on top. For comparison: the interrupt over the control step's own chain
  # alone (the benchmark image), which leaves out the frames of the loop around it. The flash driver's
  # pour_flash_write_page calls its stall hook through a pointer (flash_g4.c, the watchdog around a page erase):
  # the board sets it to flash_stall only (board_stm32g431.c), so that call is bounded by it (--indirect).
  local port=$build/firmware/ports/cortex-m4 image step isr_stack thread_stack fault_stack step_stack total_stack
  local exception=36
  image=$(python3 scripts/lib/stack_depth.py "$port"/pour_firmware.elf.ltrans*.ci --root pour_board_drive_isr \
            --root Reset_Handler --root start_up --root run --root Fault_Handler \
            --entry Reset_Handler --entry Fault_Handler --entry Default_Handler --entry pour_hal_timer_isr \
            --indirect pour_flash_write_page=flash_stall) || image=""
  step=$(python3 scripts/lib/stack_depth.py "$port"/pour_bench_control_11.elf.ltrans*.ci --root pour_control_step) || step=""
  isr_stack=$(awk -v e=$exception '$1 == "pour_board_drive_isr" {print e + $2}' <<<"$image")
  thread_stack=$(awk '$1 == "Reset_Handler" {print $2}' <<<"$image")
  fault_stack=$(awk -v e=$exception '$1 == "Fault_Handler" {print e + $2}' <<<"$image")
  step_stack=$(awk '{print $2}' <<<"$step")
  total_stack=$((${isr_stack:-99999} + ${thread_stack:-99999}))
  sed 's/^/   call graph: /' <<<"$image"
  printf '   stack: interrupt %s B (exception frame + pour_board_drive_isr chain), thread %s B (Reset_Handler: the deeper of start-up and loop), both %s B; a fault on top %s B more (%s B); interrupt over the control step alone %s B\n' \
    "${isr_stack:-?}" "${thread_stack:-?}" "$total_stack" "${fault_stack:-?}" "$((total_stack + ${fault_stack:-99999}))" \
    "$(( ${isr_stack:-0} + ${step_stack:-0} ))"
  verdict() { if [ "$1" -le "$2" ]; then echo "within"; else echo "OVER"; fi; }
  printf '   bars: interrupt worst %s instructions (bar 850: %s), as the board runs it %s (a quarter of the 50 us period at 170 MHz: 2125 cycles); stack %s B (bar 1024: %s)\n' \
    "$worst" "$(verdict "${worst:-99999}" 850)" "${board_worst:-?}" "$total_stack" "$(verdict "${total_stack:-99999}" 1024)"
  echo "-- the full drive in the simulator (bench_motor; traces in build/host/bench/):"
  if ! { cmake --preset host && cmake --build --preset host -j2 --target bench_motor; } >/dev/null; then
    echo "error: the host build failed" >&2; return 1
  fi
  mkdir -p build/host/bench
  ./build/host/bin/bench_motor --step-csv build/host/bench/current_step.csv --bus-csv build/host/bench/pour_bus.csv |
    sed 's/^/   /'
}

# --- section: lcm — host_sim and pour_controller as two processes over LCM (udpm, loopback) ------------
# Lockstep: loop rate and round trip POUR_SENSORS -> POUR_TORQUE (median, p99) over 20,000 exchanges with
# synthetic samples (the transport and the controller alone), then a 10 s pour (10,000 steps, Box2D
# included) next to the same pour in-process. Real time: a 60 s pour at 1 kHz wall clock against the
# controller's own 1 kHz loop: late and missing answers, safe-torque ticks and overruns on both sides.
# Wall-clock figures on a shared machine are noisy: they are printed, never judged.
bench_lcm() {
  local build=build/host log bin hs u ctl
  log=$(mktemp)
  echo "== lcm: host_sim <-> pour_controller over LCM (loopback) =="
  if ! { cmake --preset host && cmake --build --preset host -j2; } >"$log" 2>&1; then
    cat "$log"
    rm -f "$log"
    echo "error: the host build failed" >&2
    return 1
  fi
  rm -f "$log"
  bin=$build/bin
  hs=$build/bin/host_sim
  u="udpm://239.255.76.67:$((20000 + $$ % 20000))?ttl=0"
  echo "-- lockstep, transport + controller only (20,000 synthetic samples):"
  "$bin/pour_controller" --io "lcm:$u" --lockstep 2>/dev/null >/dev/null &
  ctl=$!
  "$bin/lcm_loop_driver" --mode lcm --url "$u" --no-sim --steps 20000 | grep -E '^(steps|lcm)' | sed 's/^/   /'
  # The silence after a run latches the controller's stale-input fault: a fresh controller per run.
  kill -INT "$ctl"; wait "$ctl"
  "$bin/pour_controller" --io "lcm:$u" --lockstep 2>/dev/null >/dev/null &
  ctl=$!
  echo "-- lockstep, a 10 s pour (10,000 steps, Box2D included), then the same pour in-process:"
  local TIMEFORMAT='wall %R s'
  { time "$hs" --policy policy/weights.h --lcm "$u" --quiet; } 2>&1 | sed 's/^/   over LCM:   /'
  { time "$hs" --policy policy/weights.h --quiet; } 2>&1 | sed 's/^/   in-process: /'
  kill -INT "$ctl"; wait "$ctl"
  echo "-- real time, 60 s at 1 kHz (controller on its own 1 kHz clock):"
  "$bin/pour_controller" --io "lcm:$u" --duration 70 2>/dev/null >"$log" &
  ctl=$!
  sleep 0.5
  "$hs" --policy policy/weights.h --lcm "$u" --realtime --set episode_s=60 --quiet | sed 's/^/   host: /'
  kill -INT "$ctl"; wait "$ctl"
  sed 's/^/   /' "$log"
  rm -f "$log"
}

# --- section: sim — the Box2D pouring world (libpoursim, host_sim --bench) --------------------------
# Real-time factor of one 10 s episode on one core (hand-written pour; by thread CPU time, which the
# other processes on a shared machine do not distort, and by wall time), the deepest resting overlap
# (contact quality) and the liquid's compression, C rollouts per second on 1 and 2 threads with the
# shipped policy, and the liquid against physics: retention curves against an ideal liquid at three fills,
# sloshing against the first mode of a rectangular tank (docs/simulator.md). Bars: >= 20x real time,
# >= 4 episodes/s on both cores, <= 1 mm overlap, onset within 5 deg, RMS gap <= 5 %, slosh within 15 %.
bench_sim() {
  local log
  log=$(mktemp)
  echo "== sim: libpoursim (Box2D 3.1, 150 particles of liquid, 1 ms steps) =="
  if ! { cmake --preset host && cmake --build --preset host -j2 --target host_sim; } >"$log" 2>&1; then
    cat "$log"
    rm -f "$log"
    echo "error: the host build of host_sim failed" >&2
    return 1
  fi
  rm -f "$log"
  echo "   machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) (other jobs slow the wall-time figures)"
  ./build/host/bin/host_sim --bench --policy policy/weights.h | sed 's/^/   /'
  cmake --build --preset host -j2 --target bench_fluid >/dev/null && ./build/host/bin/bench_fluid | sed 's/^/   /'
}

# --- section: can — the pour CAN protocol: bus load, and the full loop on real SocketCAN ------------------
# Bus load at 1 kHz from the DBC (frame bits with and without worst-case stuffing; bar 50 % of 1 Mbit/s).
# Then, in a user-mode Linux guest (tests/can/uml_run.py) on vcan0: a 10 s pour in lockstep through
# host_sim -> LCM -> can_bridge -> vcan0 -> pour_controller, its rate (steps/s, emulated kernel: every
# syscall is expensive there, so this is a floor, not the bench's rate), and the bus load measured from
# the candump capture of that pour with exact bit stuffing.
bench_can() {
  local build=build/host log guest
  log=$(mktemp)
  echo "== can: pour.dbc bus load, full loop over vcan0 in a user-mode Linux guest =="
  if ! { cmake --preset host && cmake --build --preset host -j2; } >"$log" 2>&1; then
    cat "$log"
    rm -f "$log"
    echo "error: the host build failed" >&2
    return 1
  fi
  echo "-- computed from can/pour.dbc:"
  .venv/bin/python -m pour.can.bus_load | sed 's/^/   /'
  guest=$(mktemp -d)
  cat >"$guest/loop.sh" <<EOS
B=$ROOT/$build; U="udpm://239.255.76.67:7699?ttl=0"
candump -L vcan0 > $guest/candump.log &
dump=\$!
\$B/bin/pour_controller --io can:vcan0 --lockstep --stall-ms 5000 > $guest/ctl.txt 2>&1 &
ctl=\$!
\$B/bin/can_bridge --channel vcan0 --lcm \$U > $guest/bridge.txt 2>&1 &
br=\$!
sleep 0.5
t0=\$(date +%s.%N)
\$B/bin/host_sim --policy $ROOT/policy/weights.h --lcm \$U --quiet > $guest/host.txt 2>&1
t1=\$(date +%s.%N)
kill -INT \$br \$ctl \$dump; wait \$br \$ctl \$dump
echo "\$t0 \$t1" > $guest/times.txt
EOS
  if .venv/bin/python tests/can/uml_run.py --timeout 600 -- sh "$guest/loop.sh" >"$log" 2>&1; then
    read -r t0 t1 <"$guest/times.txt"
    echo "-- lockstep 10 s pour over CAN in the guest:"
    grep -E '^lcm lockstep' "$guest/host.txt" | sed 's/^/   /'
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "   10,000 steps in %.1f s wall: %.0f steps/s\n", b - a, 10000 / (b - a) }'
    sed 's/^/   /' "$guest/bridge.txt"
    .venv/bin/python -m pour.can.bus_load --candump "$guest/candump.log" | tail -n 1 | sed 's/^/   /'
  else
    cat "$log"
    echo "error: the guest run failed" >&2
  fi
  rm -rf "$guest" "$log"
}

# --- section: weights — parse time of weights.h against its size (host_sim's C++ loader, pour.policy.weights_h) --
# The worst inputs of the 1 MiB the loaders read: an accepted header made long by one comment or by many
# comment lines, and one single token. Best of 5 runs (C) or 3 (Python) per size; ns/byte staying flat
# as the size doubles shows the parse is linear. Bar: < 100 ms for 1 MiB.
bench_weights() {
  local log
  log=$(mktemp)
  echo "== weights: weights.h parse time (tokenizer, no backtracking; docs/weights-h.md) =="
  if ! { cmake --preset host && cmake --build --preset host -j2 --target bench_weights_parse; } >"$log" 2>&1; then
    cat "$log"
    rm -f "$log"
    echo "error: the host build of bench_weights_parse failed" >&2
    return 1
  fi
  rm -f "$log"
  echo "-- C++ (host_sim, poursim_weights_parse):"
  ./build/host/bin/bench_weights_parse policy/example_weights.h | sed 's/^/   /'
  echo "-- Python (pour.policy.weights_h.parse_weights_h_bytes):"
  .venv/bin/python - <<'EOS' | sed 's/^/   /'
import time
from pathlib import Path
from pour.policy.weights_h import WeightsHError, parse_weights_h_bytes
good = Path("policy/example_weights.h").read_bytes()
key = b"#define POUR_WEIGHTS_FORMAT 1"
for what in ("accepted, one long comment", "one token (refused)"):
    print(what + ":")
    size = 1 << 17
    while size <= 1 << 20:
        data = (good.replace(key, key + b" /*" + b"x" * (size - len(good) - 6) + b" */") if "comment" in what
                else b"9" * size)
        best, verdict = 1e9, "accepted"
        for _ in range(3):
            t0 = time.perf_counter()
            try:
                parse_weights_h_bytes(data, "bench.h")
            except WeightsHError:
                verdict = "refused"
            best = min(best, time.perf_counter() - t0)
        print(f"  {len(data):7d} bytes: {1e3 * best:7.2f} ms  {1e9 * best / len(data):6.2f} ns/byte  ({verdict})")
        size <<= 1
EOS
}

# --- section: fuzz — the libFuzzer targets of tests/fuzz, each for as long as asked ------------------------
# scripts/bench.sh fuzz [seconds per target, default 300]: every target under nice, ASan+UBSan, on its
# committed corpus and dictionary. Prints per target: executions, exec/s, libFuzzer's edge coverage, the
# line coverage of the sources it drives (a second build with clang's source-based coverage replays the
# final corpus) and the findings (crash inputs, kept in build/host-fuzz/bench/<target>/ for a regression).
FUZZ_TARGETS=(fuzz_weights_h fuzz_config fuzz_control_step fuzz_can_node fuzz_lcm_decode fuzz_lcm_port)
fuzz_sources() {
  case $1 in
    fuzz_weights_h) echo host_sim/physics/weights_file.cpp ;;
    fuzz_config) echo host_sim/physics/config.cpp ;;
    fuzz_control_step) echo firmware/src/control.c firmware/src/safety.c firmware/src/sensors.c firmware/src/supervisor.c firmware/src/policy.c firmware/src/obs.c ;;
    fuzz_can_node) echo firmware/can/src/can_node.c firmware/can/src/can_codec.c firmware/src/control.c firmware/src/safety.c ;;
    fuzz_lcm_decode) echo build/host-fuzz-cov/lcmtypes/c/pour_sensor_sample_t.c build/host-fuzz-cov/lcmtypes/c/pour_command_t.c \
                          build/host-fuzz-cov/lcmtypes/c/pour_torque_t.c ;;
    fuzz_lcm_port) echo firmware/ports/linux/io_lcm.c ;;
  esac
}
bench_fuzz() {
  local seconds=${FUZZ_SECONDS:-300} log t work cov stats
  log=$(mktemp)
  echo "== fuzz: libFuzzer targets (clang-14, ASan+UBSan), ${seconds} s each, nice 10 =="
  cov=build/host-fuzz-cov
  if ! { cmake --preset host-fuzz && cmake --build --preset host-fuzz &&
         cmake -S . -B "$cov" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOUR_FUZZ=ON \
           -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
           "-DCMAKE_C_FLAGS=-fprofile-instr-generate -fcoverage-mapping -fsanitize=fuzzer-no-link" \
           "-DCMAKE_CXX_FLAGS=-fprofile-instr-generate -fcoverage-mapping -fsanitize=fuzzer-no-link" \
           -DCMAKE_EXE_LINKER_FLAGS=-fprofile-instr-generate -DCMAKE_SHARED_LINKER_FLAGS=-fprofile-instr-generate &&
         cmake --build "$cov" --target pour_fuzz_all; } >"$log" 2>&1; then
    cat "$log"
    rm -f "$log"
    echo "error: the fuzz builds failed" >&2
    return 1
  fi
  rm -f "$log"
  echo "   machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
  local findings=0
  for t in "${FUZZ_TARGETS[@]}"; do
    work=build/host-fuzz/bench
    rm -rf "${work:?}/$t"
    nice -n 10 tests/fuzz/run_fuzz.sh "build/host-fuzz/bin/$t" "$seconds" "$work" >"$work.$t.log" 2>&1
    stats=$(awk '/stat::number_of_executed_units/ {n = $2} /stat::average_exec_per_sec/ {r = $2}
                 /(DONE|INITED) +cov: / {c = $0; sub(/.*cov: /, "", c); sub(/ .*/, "", c)}
                 END {printf "%s executions, %s exec/s, %s edges", n, r, c}' "$work.$t.log")
    # Line coverage: the coverage build replays the corpus the run ended with.
    rm -f "$work/$t"/*.profraw
    LLVM_PROFILE_FILE="$work/$t/%p.profraw" "$cov/bin/$t" -runs=0 "$work/$t/corpus" "tests/fuzz/corpus/$t" \
      >/dev/null 2>&1 || true
    local lines="?"
    if llvm-profdata-14 merge -sparse "$work/$t"/*.profraw -o "$work/$t/all.profdata" 2>/dev/null; then
      # shellcheck disable=SC2046
      lines=$(llvm-cov-14 export -summary-only -instr-profile="$work/$t/all.profdata" "$cov/bin/$t" \
                $(fuzz_sources "$t") 2>/dev/null | python3 -c '
import json, sys
t = json.load(sys.stdin)["data"][0]["totals"]["lines"]
print("%d/%d lines (%.1f %%)" % (t["covered"], t["count"], t["percent"]))' || echo "?")
    fi
    local crashes
    crashes=$(find "$work/$t" -maxdepth 1 \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l)
    findings=$((findings + crashes))
    printf '   %-18s %s; line coverage of %s: %s; findings: %s\n' "$t" "$stats" \
      "$(fuzz_sources "$t" | tr ' ' '\n' | xargs -n1 basename | paste -sd, -)" "$lines" "$crashes"
    if [ "$crashes" != 0 ]; then
      grep -m1 -E 'property broken|ERROR: ' "$work.$t.log" | sed 's/^/      /'
    fi
  done
  echo "   findings in all: $findings (inputs in build/host-fuzz/bench/<target>/)"
}

# --- section: vboard — the flashed image's interrupts and 1 kHz step, counted on the virtual board ---------
# pour_virtual_board --profile on pour_firmware.elf (the file scripts/flash.sh flashes), idle for 10 s and in
# the closed-loop pour (--pour: calibrated, the shipped policy deciding): each exception handler by its vector
# and the ELF's symbol, instructions of its own and with what nests in it, and its share of the 50 us
# current-loop period at 170 MHz; the 1 kHz loop tick (pour_board_loop_tick), the core's step
# (pour_control_step) and the decision (pour_policy_decide), with and without the interrupts that preempt
# them. Cycles are a model: instructions x CPI 1.000 + 12 + 10 per exception (docs/virtual-board.md,
# "Cycle counts"). Bar: the control step <= 1,000 instructions excluding interrupts, in the pour (every
# decision tick) and idle (ctest py_test_vboard_profile).
bench_vboard() {
  local log out worst
  log=$(mktemp)
  echo "== vboard: the flashed image on the virtual board (pour_virtual_board --profile, 10 s emulated) =="
  if ! { cmake --preset cortex-m4 && cmake --build --preset cortex-m4 -j2 --target pour_firmware &&
         cmake --preset host && cmake --build --preset host -j2 --target pour_virtual_board; } >"$log" 2>&1; then
    cat "$log"; rm -f "$log"; echo "error: the build of the image or of the virtual board failed" >&2; return 1
  fi
  rm -f "$log"
  local what args
  for what in idle pour; do
    if [ "$what" = idle ]; then args=(--seconds 10); else args=(--pour --seed 1); fi
    echo "-- $what (pour_virtual_board ${args[*]} --profile):"
    if ! out=$(build/host/bin/pour_virtual_board "${args[@]}" --profile 2>&1); then
      echo "$out"; echo "error: the virtual board stopped" >&2; return 1
    fi
    grep -E '^(profile:|virtual board: .*sha256|episode)' <<<"$out" | sed -e 's/^profile: /   /' -e 's/^virtual board: /   /' -e 's/^episode/   episode/'
    worst=$(sed -nE 's/^profile: function pour_control_step[^:]*: [0-9]+ calls, instructions excluding interrupts mean [0-9.]+ worst ([0-9]+).*/\1/p' <<<"$out")
    printf '   bar: the control step on the image (%s), worst %s instructions excluding interrupts (bar 1000: %s)\n' \
      "$what" "${worst:-?}" "$([ "${worst:-99999}" -le 1000 ] && echo within || echo OVER)"
  done
}

# --- section: suite, suite-all — the test suite's wall time ------------------------------------------
# Runs ./scripts/test.sh (or --all) and prints its table of wall time by preset (configure and build, then
# ctest -j) with the machine's load. Bar: the quick suite <= 10 min on 2 cores once built; --all well under
# CI's 90 min.
bench_suite_run() {
  local log rc
  log=$(mktemp)
  echo "== suite: ./scripts/test.sh $* ($(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)) =="
  ./scripts/test.sh "$@" >"$log" 2>&1
  rc=$?
  sed -n '/^wall time by preset/,$p' "$log" | sed 's/^/   /'
  [ "$rc" = 0 ] || echo "   (the suite failed, exit $rc; its log: $log)"
  [ "$rc" = 0 ] && rm -f "$log"
  return "$rc"
}
bench_suite() { bench_suite_run; }
bench_suite-all() { bench_suite_run --all; }

SECTIONS=(core motor lcm sim can weights fuzz suite suite-all vboard)
wanted=()
for a in "$@"; do
  # `fuzz 600`: the number is the seconds each fuzz target runs.
  if [[ $a =~ ^[0-9]+$ ]] && [ ${#wanted[@]} -gt 0 ] && [ "${wanted[-1]}" = fuzz ]; then
    FUZZ_SECONDS=$a
  else
    wanted+=("$a")
  fi
done
[ ${#wanted[@]} -gt 0 ] || wanted=(core motor lcm sim can weights) # fuzz and suite only when asked: minutes
status=0
for s in "${wanted[@]}"; do
  if [[ " ${SECTIONS[*]} " != *" $s "* ]]; then
    echo "error: unknown section '$s' (sections: ${SECTIONS[*]})" >&2
    exit 2
  fi
  "bench_$s" || status=1
  echo
done
exit "$status"
