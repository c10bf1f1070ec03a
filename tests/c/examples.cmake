# The example programs end to end (examples/*_ode.c and their steadystep adoptions, targets steadystep_example_*),
# included from CMakeLists.txt.
#  - Each adopted program runs 10 s of 15-45 fps frames under every policy and exits 0: every frame stepped.
#  - Each plain program runs the same frames and exits 0.
#  - Adopted with the naive policy (one step a frame, the numbers as tuned at 60 fps), a program moves as its own
#    stepping does, bit for bit: the same CSV bytes at 60, 30, 15-45 and 120 fps. This checks that adoption reads
#    back exactly what the program tuned (world, joints, contacts, damping, auto-disable), and that the stepper keeps
#    the program's forces and solver settings.
#  - Bad flags exit with 2 and name the flag.
set(STEADYSTEP_EXAMPLE_PROGRAMS vehicle chain stack)
set(STEADYSTEP_EXAMPLE_POLICIES naive implicit-euler matched exact fixed fixed-matched fixed-exact)

foreach(program ${STEADYSTEP_EXAMPLE_PROGRAMS})
  add_test(NAME example_${program}_ode_uniform
           COMMAND steadystep_example_${program}_ode --profile uniform:15:45 --duration 10 --seed 1 --quiet)
  foreach(policy ${STEADYSTEP_EXAMPLE_POLICIES})
    add_test(NAME example_${program}_steadystep_${policy}_uniform
             COMMAND steadystep_example_${program}_steadystep --policy ${policy} --profile uniform:15:45 --duration 10
                     --seed 1 --quiet)
  endforeach()

  # Naive adoption against the program's own stepping: byte-identical CSV, 10 s at 60, 30 and 15-45 fps and above
  # the tuned rate (120 fps, frames shorter than the tuned step), and every row present.
  foreach(profile fixed:60 fixed:30 uniform:15:45 fixed:120)
    string(REPLACE ":" "_" profile_name ${profile})
    add_test(NAME example_${program}_naive_is_own_stepping_${profile_name}
             COMMAND sh -c "\"$1\" --profile $4 --duration 10 --seed 3 > \"$3.ode.csv\" && \
\"$2\" --policy naive --profile $4 --duration 10 --seed 3 > \"$3.naive.csv\" && \
rows=$(wc -l < \"$3.ode.csv\") && test \"$rows\" -gt 100 && cmp \"$3.ode.csv\" \"$3.naive.csv\" && \
echo \"$rows rows, byte-identical\""
                     sh $<TARGET_FILE:steadystep_example_${program}_ode>
                     $<TARGET_FILE:steadystep_example_${program}_steadystep>
                     ${CMAKE_CURRENT_BINARY_DIR}/example_${program}_naive_${profile_name} ${profile})
  endforeach()

  # A pass expression overrides the exit code, so the code is printed and matched too.
  add_test(NAME example_${program}_bad_policy
           COMMAND sh -c "\"$1\" --policy sideways --duration 1 2>&1; echo exit $?"
                   sh $<TARGET_FILE:steadystep_example_${program}_steadystep>)
  set_tests_properties(example_${program}_bad_policy PROPERTIES PASS_REGULAR_EXPRESSION
                       "--policy sideways: [^\n]*\nexit 2\n")
  add_test(NAME example_${program}_bad_profile
           COMMAND sh -c "\"$1\" --profile uniform:45:15 2>&1; echo exit $?"
                   sh $<TARGET_FILE:steadystep_example_${program}_ode>)
  set_tests_properties(example_${program}_bad_profile PROPERTIES PASS_REGULAR_EXPRESSION
                       "--profile uniform:45:15: [^\n]*\nexit 2\n")
  add_test(NAME example_${program}_csv_header
           COMMAND steadystep_example_${program}_steadystep --profile fixed:30 --duration 0.1)
endforeach()

# A program that is both halves in one binary (without --policy it steps on its own) prints the same bytes adopted
# under naive, in its followed columns (the first `columns`; those after count what served the rows, -1 on its own),
# at each of the profiles: 10 s, every row present.
function(steadystep_naive_is_own_stepping name target columns)
  foreach(profile ${ARGN})
    string(REPLACE ":" "_" profile_name ${profile})
    add_test(NAME ${name}_naive_is_own_stepping_${profile_name}
             COMMAND sh -c "\"$1\" --profile $3 --duration 10 --seed 3 | cut -d, -f1-$4 > \"$2.ode.csv\" && \
\"$1\" --policy naive --profile $3 --duration 10 --seed 3 | cut -d, -f1-$4 > \"$2.naive.csv\" && \
rows=$(wc -l < \"$2.ode.csv\") && test \"$rows\" -gt 100 && cmp \"$2.ode.csv\" \"$2.naive.csv\" && \
echo \"$rows rows, byte-identical\""
             sh $<TARGET_FILE:${target}> ${CMAKE_CURRENT_BINARY_DIR}/${name}_naive_${profile_name} ${profile}
             ${columns})
  endforeach()
endfunction()

# The audit's double pendulum (examples/audit_pendulum.c). Chaotic: a difference of one rounding would show within
# seconds.
steadystep_naive_is_own_stepping(example_audit_pendulum steadystep_example_audit_pendulum 3
                                 fixed:60 fixed:30 uniform:15:45 fixed:120)
# The game-like program (examples/wrecking_arm.c): its logic once a frame on its own, before every step adopted, and
# its wind added once a frame either way.
steadystep_naive_is_own_stepping(example_wrecking_arm steadystep_example_wrecking_arm 4
                                 fixed:60 fixed:30 uniform:15:45 fixed:120)
# A program that substeps itself (three dWorldStep substeps a frame, tests/c/substepping_program.c), adopted with one
# ssStepper_Step per substep.
add_executable(steadystep_test_substepping_program tests/c/substepping_program.c)
target_link_libraries(steadystep_test_substepping_program PRIVATE steadystep_lab m)
steadystep_naive_is_own_stepping(substepping_program steadystep_test_substepping_program 3
                                 fixed:60 fixed:30 fixed:144 uniform:15:45)

# The game-like program steps 10 s of 15-45 fps frames under every policy, and on its own.
foreach(policy ${STEADYSTEP_EXAMPLE_POLICIES})
  add_test(NAME example_wrecking_arm_${policy}_uniform
           COMMAND sh -c "\"$1\" --policy $2 --profile uniform:15:45 --duration 10 --seed 1 > /dev/null"
                   sh $<TARGET_FILE:steadystep_example_wrecking_arm> ${policy})
endforeach()

# Identical motion at every frame rate, the README's way: each program adopted under fixed, its per-step logic in
# before_step at the step's time, forces added once a frame held, rows labelled with the stepper's clock, prints the
# same bytes at every simulated time its runs at 144, 60, 30, 15-45 (three seeds) and jittered 60 fps share.
foreach(program vehicle_steadystep:3 chain_steadystep:3 stack_steadystep:3 audit_pendulum:3 wrecking_arm:4
                oscillator:5)
  string(REPLACE ":" ";" parts ${program})
  list(GET parts 0 name)
  list(GET parts 1 columns)
  add_test(NAME example_${name}_fixed_is_the_same_at_every_frame_rate
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/tests/c/same_at_every_rate.sh $<TARGET_FILE:steadystep_example_${name}>
                   ${columns} ${CMAKE_CURRENT_BINARY_DIR}/example_${name}_fixed --duration 10)
  set_tests_properties(example_${name}_fixed_is_the_same_at_every_frame_rate PROPERTIES PASS_REGULAR_EXPRESSION
                       "rows at shared times, byte-identical")
endforeach()

# A 60 fps game with ordinary jitter, or on a 59 Hz display, takes about one physics step a frame under implicit
# Euler (the slack, stepping.h), not 1.5: the steps column of the audit programs' rows, averaged over 20 s.
foreach(program audit_pendulum:4 wrecking_arm:5)
  string(REPLACE ":" ";" parts ${program})
  list(GET parts 0 name)
  list(GET parts 1 steps_column)
  foreach(profile jitter:60:2 vsync:60:59)
    string(REPLACE ":" "_" profile_name ${profile})
    add_test(NAME example_${name}_about_one_step_a_frame_at_${profile_name}
             COMMAND sh -c "\"$1\" --policy implicit-euler --profile $2 --duration 20 | awk -F, -v c=$3 \
'NR > 2 { steps += $c; frames += 1 } END { ok = frames > 1000 && steps / frames <= 1.05; \
printf \"%.4f steps a frame over %d frames: %s\\n\", steps / frames, frames, ok ? \"at most 1.05\" : \"too many\" }'"
                     sh $<TARGET_FILE:steadystep_example_${name}> ${profile} ${steps_column})
    set_tests_properties(example_${name}_about_one_step_a_frame_at_${profile_name} PROPERTIES
                         PASS_REGULAR_EXPRESSION "steps a frame over [0-9]+ frames: at most 1.05")
  endforeach()
endforeach()

set_tests_properties(example_vehicle_csv_header PROPERTIES PASS_REGULAR_EXPRESSION
                     "^t_s,height_m,pitch_rad\n0,[^\n]+\n0\\.0333")
set_tests_properties(example_chain_csv_header PROPERTIES PASS_REGULAR_EXPRESSION
                     "^t_s,end_x_m,end_z_m\n0,[^\n]+\n0\\.0333")
set_tests_properties(example_stack_csv_header PROPERTIES PASS_REGULAR_EXPRESSION
                     "^t_s,top_z_m,ground_force_N\n0,[^\n]+\n0\\.0333")
add_test(NAME example_stack_bad_boxes
         COMMAND sh -c "\"$1\" --boxes 0 2>&1; echo exit $?" sh $<TARGET_FILE:steadystep_example_stack_steadystep>)
set_tests_properties(example_stack_bad_boxes PROPERTIES PASS_REGULAR_EXPRESSION "--boxes 0: [^\n]*\nexit 2\n")

# The README's code: its C blocks compiled as C and as C++ against the library (stubs for the program around it in
# tests/c/readme_snippet.sh, not in the README), and docs/adopting.md's diff the output of the command it names
# (scripts/adopting-diff rewrites it).
if(NOT STEADYSTEP_SANITIZE)  # a sanitized library needs its runtime linked first, as for the install test
  set(readme_ode_runpath "")  # an ODE outside the system's directories (STEADYSTEP_ODE_PREFIX) is found at run time
  foreach(dir ${ODE_LIBRARY_DIRS})
    list(APPEND readme_ode_runpath "-Wl,-rpath,${dir}")
  endforeach()
  add_test(NAME readme_c_blocks_compile_as_c_and_cpp
           COMMAND sh ${PROJECT_SOURCE_DIR}/tests/c/readme_snippet.sh ${PROJECT_SOURCE_DIR}/README.md
                   ${CMAKE_C_COMPILER} ${CMAKE_CXX_COMPILER} ${CMAKE_CURRENT_BINARY_DIR}/readme_snippet
                   $<TARGET_FILE:steadystep> ${PROJECT_SOURCE_DIR}/include -I${STEADYSTEP_GENERATED_INCLUDE} ${ODE_CFLAGS}
                   ${ODE_LDFLAGS}
                   ${readme_ode_runpath})
endif()
find_package(Python3 COMPONENTS Interpreter REQUIRED)
add_test(NAME adopting_diff_is_current
         COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/scripts/adopting-diff --check)
