#!/usr/bin/env bash
# Cross-compile the gyrocal C library for a Cortex-M4F, run the on-device calibration example under
# qemu-system-arm (mps2-an386, semihosting) and print code size, peak stack use and executed instructions.
# Then build the example firmware of examples/firmware (gyrocal frames, on-device six-turn session) with a
# QEMU board layer, run it, and compare every byte it sends with the same firmware built for the host.
#
# Usage: tools/cross_m4.sh [BUILD_DIR]        (run by hand, not in CI; installs what it needs with apt-get)
#
# Instruction counts: QEMU runs with one guest instruction per translation block and no block chaining
# (-singlestep, or -accel tcg,one-insn-per-tb=on on QEMU >= 8.1) and logs every executed block
# (-d exec,nochain), so every log line is one executed instruction. The count of a call is the number
# of lines between marker_begin() and marker_end() in tools/m4/main.c: the call itself, its argument
# set-up and the return, nothing of the markers.
# Peak stack: the free stack is painted before each call and scanned after it (figures printed by the
# example), next to GCC's static -fstack-usage figures. The example is also built for the host with the
# system cc, and its results are compared with the emulated M4's bit for bit.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/.." && pwd)"
csrc="$root/src/gyrocal/c"
m4="$here/m4"
build="${1:-$(mktemp -d /tmp/gyrocal-m4.XXXXXX)}"
mkdir -p "$build"

need=()
command -v arm-none-eabi-gcc >/dev/null || need+=(gcc-arm-none-eabi)
[ -e /usr/lib/arm-none-eabi/include/stdint.h ] || need+=(libnewlib-arm-none-eabi)
command -v qemu-system-arm >/dev/null || need+=(qemu-system-arm)
if [ ${#need[@]} -gt 0 ]; then
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    echo "installing ${need[*]} with apt-get"
    $sudo apt-get update
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${need[@]}"
fi

CFLAGS=(-std=c99 -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os -fno-math-errno
        -ffunction-sections -fdata-sections -fstack-usage -Wall -Wextra -Wdouble-promotion)
echo "== toolchain: $(arm-none-eabi-gcc --version | head -1); $(qemu-system-arm --version | head -1)"
echo "== flags: ${CFLAGS[*]}"

for unit in gyrocal_cal gyrocal_frame gyrocal_session; do
    arm-none-eabi-gcc "${CFLAGS[@]}" -I"$csrc" -c "$csrc/$unit.c" -o "$build/$unit.o"
done
arm-none-eabi-gcc "${CFLAGS[@]}" -I"$csrc" -I"$m4" -c "$m4/main.c" -o "$build/main.o"
# The start-up copies must not become calls to memcpy/memset: there is no libc.
arm-none-eabi-gcc "${CFLAGS[@]}" -fno-tree-loop-distribute-patterns -I"$m4" -c "$m4/startup.c" -o "$build/startup.o"
arm-none-eabi-gcc "${CFLAGS[@]}" -nostdlib -nostartfiles -T "$m4/mps2_an386.ld" -Wl,--gc-sections \
    "$build/startup.o" "$build/main.o" "$build/gyrocal_cal.o" -lgcc -o "$build/example.elf"

echo "== code size of the library (calibration, correction, thermal table, accumulator; frame encoder; session), bytes:"
arm-none-eabi-size "$build/gyrocal_cal.o" "$build/gyrocal_frame.o" "$build/gyrocal_session.o"
undefined="$(arm-none-eabi-nm -u "$build/gyrocal_cal.o" | tr -s ' \n' ' ')"
echo "   undefined symbols (must be none): ${undefined:-none}"
echo "== static RAM of an on-device calibration (the example's accumulator and six observations), bytes:"
total=0
while read -r _ size _ name; do
    case "$name" in obs|obs.*|acc|acc.*)
        printf '   %-10s %5d\n' "$name" $((16#$size)); total=$((total + 16#$size)) ;;
    esac
done < <(arm-none-eabi-nm -S "$build/main.o")
printf '   total      %5d\n' "$total"
echo "== whole example image (library, example, start-up):"
arm-none-eabi-size "$build/example.elf"

echo "== the whole-IMU temperature table (gyrocal_imu_thermal_correct with the GYROCAL_IMU_THERMAL of tools/m4/imu_thermal_cal.h):"
echo "   flash (text and const data) in the example image, bytes:"
imu_flash=0
while read -r addr size type name; do
    case "$name" in gyrocal_imu_thermal_correct|gyrocal_poly_correct|finite3|GYROCAL_IMU_THERMAL)
        where="flash"
        [ $((16#$addr)) -lt $((16#20000000)) ] || where="RAM"
        printf '   %-30s %5d  (%s, in %s)\n' "$name" $((16#$size)) "$type" "$where"
        imu_flash=$((imu_flash + 16#$size)) ;;
    esac
done < <(arm-none-eabi-nm -S "$build/example.elf")
printf '   total                          %5d\n' "$imu_flash"
imu_ram="$(arm-none-eabi-size -A "$build/gyrocal_cal.o" | awk '$1 ~ /^\.(data|bss)/ { s += $2 } END { print s + 0 }')"
echo "   static RAM: library data + bss $imu_ram B (the table is const, in flash; outputs on the caller's stack)"

echo "== static stack use per function (-fstack-usage), bytes:"
awk -F'\t' '{ sub(/^.*:/, "", $1); printf "   %-30s %5s  %s\n", $1, $2, $3 }' "$build/gyrocal_cal.su"

qemu=(qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none
      -semihosting-config enable=on,target=native -kernel "$build/example.elf")
echo "== run under ${qemu[*]}"
"${qemu[@]}" 2>&1 | tee "$build/m4.out"

if command -v cc >/dev/null; then
    echo "== the same example built for the host ($(cc --version | head -1)): float32 results bit for bit"
    cc -std=c99 -O2 -DGYROCAL_HOST -I"$csrc" -I"$m4" "$m4/main.c" "$csrc/gyrocal_cal.c" -lm -o "$build/host_example"
    "$build/host_example" > "$build/host.out"
    if diff <(grep -E 'status|bits' "$build/m4.out") <(grep -E 'status|bits' "$build/host.out"); then
        echo "   identical: every k, b and corrected rate has the same float32 bits on the M4 and on the host"
    else
        echo "   DIFFERENT (see the diff above)"
    fi
else
    echo "== no host cc: skipping the bit-for-bit comparison with the host"
fi

ver="$(qemu-system-arm --version | sed -n 's/.*version \([0-9]*\)\.\([0-9]*\).*/\1 \2/p')"
read -r major minor <<<"$ver"
if [ "$major" -gt 8 ] || { [ "$major" -eq 8 ] && [ "$minor" -ge 1 ]; }; then
    onebyone=(-accel tcg,one-insn-per-tb=on)
else
    onebyone=(-singlestep)
fi
fifo="$build/trace.fifo"
rm -f "$fifo"
mkfifo "$fifo"
awk '
    / marker_begin/ { inside = 1; n = 0; next }
    / marker_end/   { if (inside == 1) { counts[++k] = n }; inside = 0; next }
    inside == 1     { n++ }
    END {
        label[1] = "gyrocal_accum_add, one sample"; label[2] = "gyrocal_algorithm1, six observations"
        label[3] = "gyrocal_first_moment, six observations"; label[4] = "gyrocal_correct, one sample"
        label[5] = "gyrocal_thermal_correct, one sample"
        label[6] = "gyrocal_imu_thermal_correct, one sample"
        print "== executed instructions (QEMU trace, one instruction per block):"
        for (i = 1; i <= k; i++) printf "   %-40s %7d\n", label[i], counts[i]
    }' "$fifo" &
counter=$!
"${qemu[@]}" "${onebyone[@]}" -d exec,nochain -D "$fifo" >/dev/null 2>&1
wait "$counter"
rm -f "$fifo"
echo "== the example firmware (examples/firmware) on the emulated M4: frames from the six-turn session"
ex="$root/examples/firmware"
arm-none-eabi-gcc "${CFLAGS[@]}" -I"$csrc" -I"$ex" -I"$m4" -c "$ex/gyrocal_example.c" -o "$build/gyrocal_example.o"
# The board layer's byte copies (board_store, board_load) must not become calls to memcpy: there is no libc.
arm-none-eabi-gcc "${CFLAGS[@]}" -fno-tree-loop-distribute-patterns -I"$csrc" -I"$ex" -I"$m4" -c "$ex/qemu_board.c" \
    -o "$build/qemu_board.o"
arm-none-eabi-gcc "${CFLAGS[@]}" -nostdlib -nostartfiles -T "$m4/mps2_an386.ld" -Wl,--gc-sections \
    "$build/startup.o" "$build/qemu_board.o" "$build/gyrocal_example.o" "$build/gyrocal_session.o" \
    "$build/gyrocal_frame.o" "$build/gyrocal_cal.o" -lgcc -o "$build/firmware.elf"
echo "   portable firmware (example loop + session + frames + library, no board layer), bytes:"
arm-none-eabi-size "$build/gyrocal_example.o"
echo "   whole image with the QEMU board layer and start-up (gc-sections), bytes:"
arm-none-eabi-size "$build/firmware.elf"
"${qemu[@]/example.elf/firmware.elf}" > "$build/firmware_m4.hex" 2>&1
cc -std=c99 -O2 -DGYROCAL_HOST -I"$csrc" -I"$ex" -I"$m4" "$ex/qemu_board.c" "$ex/gyrocal_example.c" \
    "$csrc/gyrocal_session.c" "$csrc/gyrocal_frame.c" "$csrc/gyrocal_cal.c" -lm -o "$build/firmware_host"
"$build/firmware_host" > "$build/firmware_host.hex"
echo "   frames sent: $(wc -l < "$build/firmware_m4.hex") (M4), $(wc -l < "$build/firmware_host.hex") (host)"
if cmp -s "$build/firmware_m4.hex" "$build/firmware_host.hex"; then
    echo "   identical: every byte the M4 sent equals the host build's"
else
    echo "   DIFFERENT: compare $build/firmware_m4.hex and $build/firmware_host.hex"
fi
echo "== build folder: $build"
