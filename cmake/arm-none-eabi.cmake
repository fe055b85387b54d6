# SPDX-License-Identifier: MIT
# Cross toolchain for the Cortex-M4 firmware: Debian's gcc-arm-none-eabi, soft-float ABI.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR cortex-m4)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_OBJCOPY arm-none-eabi-objcopy CACHE FILEPATH "objcopy")
set(CMAKE_SIZE arm-none-eabi-size CACHE FILEPATH "size")
set(CMAKE_NM arm-none-eabi-nm CACHE FILEPATH "nm")
set(CMAKE_READELF arm-none-eabi-readelf CACHE FILEPATH "readelf")

# The fixed-point core must never need an FPU: soft-float ABI everywhere. Link-time optimisation across the
# core, the CAN node, the drive and the port (~3 KB less flash and ~5 % fewer instructions per control tick
# than per-object optimisation; scripts/bench.sh core). Fat objects keep real code beside the LTO bytecode,
# so per-object sizes and readelf's symbol tables stay meaningful; one partition gives one call graph per
# image (-fcallgraph-info=su: <image>.ltrans0.ltrans.ci), from which scripts/bench.sh takes the stack depths
# that -fstack-usage's per-object .su files gave before inlining across files.
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m4 -mthumb -mfloat-abi=soft -ffunction-sections -fdata-sections -flto -ffat-lto-objects")
set(CMAKE_ASM_FLAGS_INIT "-mcpu=cortex-m4 -mthumb -mfloat-abi=soft")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,--gc-sections -flto -flto-partition=one -fcallgraph-info=su")

set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)

# Unit tests run on QEMU's mps2-an386 board (Cortex-M4); the exit status comes back via semihosting.
set(CMAKE_CROSSCOMPILING_EMULATOR
    qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none
    -semihosting-config enable=on,target=native -kernel)
