#!/bin/sh
# The README's C blocks, all of them in one program, compiled as C and as C++ against the library and linked, as a
# program would: with the stubs below for what the blocks take from the program around it (its world, space,
# contact group, a car and its motor, a frame clock, a renderer, a repair), which stay out of the README. The
# program built is run once (it returns at once) to show that it loads the library.
#   readme_snippet.sh README.md CC CXX WORK_DIR LIBRARY INCLUDE_DIR [ODE compile and link flags...]
set -eu
readme=$1 cc=$2 cxx=$3 work=$4 library=$5 include=$6
shift 6
mkdir -p "$work"
awk '/^```c$/ { inside = 1; found += 1; next } inside && /^```$/ { inside = 0; print ""; next } inside { print }
     END { exit found < 2 }' "$readme" > "$work/snippet.inc" || { echo "$readme: fewer than two \`\`\`c blocks"; exit 1; }
cat > "$work/readme.c" <<'PROGRAM'
/* What the README's block takes from the program around it. */
#include <math.h>
#include <stdio.h>

#include <ode/ode.h>

static dWorldID world;
static dSpaceID space;
static dJointGroupID contacts;
static dBodyID car;
static dJointID motor;
static double throttle = 1.0;
static double next_frame_seconds(void) { return 1.0 / 60; }
static void draw(const double position[3], const double quaternion[4]) { (void)position, (void)quaternion; }
static void restore_last_good_state(void) {}

#include "snippet.inc"

int main(int argc, char** argv) {
  (void)argv;
  return argc > 99 ? run_game() + run_game_variable_steps() : 0; /* compiled and linked, never run: no world */
}
PROGRAM
cp "$work/readme.c" "$work/readme.cpp"
flags="-Wall -Wextra -Werror -I$include"
libdir=$(dirname "$library")
# shellcheck disable=SC2086 # the flags are words
"$cc" -std=c17 $flags -o "$work/readme_c" "$work/readme.c" "$library" -Wl,-rpath,"$libdir" "$@" -lm
# shellcheck disable=SC2086
"$cxx" -std=c++17 $flags -o "$work/readme_cpp" "$work/readme.cpp" "$library" -Wl,-rpath,"$libdir" "$@" -lm
"$work/readme_c"
"$work/readme_cpp"
echo "README.md's C blocks: compiled as C and as C++, linked against $(basename "$library"), both run"
