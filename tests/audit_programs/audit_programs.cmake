# The audit's test programs (tests/audit_programs/*.c), linked to the core alone: STEADYSTEP_AUDIT_PROGRAMS_CORE
# (default the project's steadystep target; tests/audit_programs/CMakeLists.txt sets the installed one). Each is
# built as steadystep_audit_<name>; ctest checks each one's protocol header and t = 0 row, and that it refuses a
# bad flag with exit 2. protocol_cxx.cpp uses the header from C++: the frames it reads from STEADYSTEP_AUDIT_FRAMES
# (frames.txt: 0.25 and 0.5 s, repeated) and from fixed:FPS, and a random profile refused by name without them.
if(NOT DEFINED STEADYSTEP_AUDIT_PROGRAMS_CORE)
  set(STEADYSTEP_AUDIT_PROGRAMS_CORE steadystep)
endif()
set(STEADYSTEP_AUDIT_PROGRAMS_DIR ${CMAKE_CURRENT_LIST_DIR})
foreach(name box_stack ragdoll maze hopper)
  add_executable(steadystep_audit_${name} ${STEADYSTEP_AUDIT_PROGRAMS_DIR}/${name}.c)
  target_link_libraries(steadystep_audit_${name} PRIVATE ${STEADYSTEP_AUDIT_PROGRAMS_CORE} m)
  if(BUILD_TESTING OR STEADYSTEP_TESTS)
    add_test(NAME audit_program_${name}_csv
             COMMAND steadystep_audit_${name} --policy fixed --profile fixed:30 --duration 0.1)
    set_tests_properties(audit_program_${name}_csv PROPERTIES PASS_REGULAR_EXPRESSION
                         "^t_s,[^\n]+,steps,rows_by_mapping,[^\n]+\n0,[^\n]+,0,0,0,0,0,0,0\n0\\.0[0-9]+,[^\n]+\n")
    add_test(NAME audit_program_${name}_bad_flag
             COMMAND sh -c "\"$1\" --policy sideways 2>&1; echo exit $?" sh $<TARGET_FILE:steadystep_audit_${name}>)
    set_tests_properties(audit_program_${name}_bad_flag PROPERTIES PASS_REGULAR_EXPRESSION
                         "${name}: --policy sideways: [^\n]*\nexit 2\n")
  endif()
endforeach()

# box_stack_unsoftened: the box stack whose near callback forgets ssStepper_SoftenContact: every step under a policy
# makes contacts and softens none, which the unsoftened_contact_steps column counts.
add_executable(steadystep_audit_box_stack_unsoftened ${STEADYSTEP_AUDIT_PROGRAMS_DIR}/box_stack.c)
target_compile_definitions(steadystep_audit_box_stack_unsoftened PRIVATE GAME_FORGETS_SOFTEN=1)
target_link_libraries(steadystep_audit_box_stack_unsoftened PRIVATE ${STEADYSTEP_AUDIT_PROGRAMS_CORE} m)
if(BUILD_TESTING OR STEADYSTEP_TESTS)
  add_test(NAME audit_program_box_stack_unsoftened_counted
           COMMAND steadystep_audit_box_stack_unsoftened --policy exact --profile fixed:30 --duration 0.1)
  set_tests_properties(audit_program_box_stack_unsoftened_counted PROPERTIES PASS_REGULAR_EXPRESSION
                       ",unsoftened_contact_steps\n0,[^\n]+,0,0,0,0,0,0,0,0\n0\\.0[0-9]+,[^\n]+,0,0,0,[1-9][0-9]*\n")
  add_test(NAME audit_program_box_stack_softened_counted
           COMMAND steadystep_audit_box_stack --policy exact --profile fixed:30 --duration 0.1)
  set_tests_properties(audit_program_box_stack_softened_counted PROPERTIES PASS_REGULAR_EXPRESSION
                       ",unsoftened_contact_steps\n0,[^\n]+,0,0,0,0,0,0,0,0\n0\\.0[0-9]+,[^\n]+,([1-9][0-9]*,[0-9]+,[0-9]+|[0-9]+,[1-9][0-9]*,[0-9]+|[0-9]+,[0-9]+,[1-9][0-9]*),0\n")
endif()

add_executable(steadystep_audit_protocol_cxx ${STEADYSTEP_AUDIT_PROGRAMS_DIR}/protocol_cxx.cpp)
target_link_libraries(steadystep_audit_protocol_cxx PRIVATE ${STEADYSTEP_AUDIT_PROGRAMS_CORE} m)
if(BUILD_TESTING OR STEADYSTEP_TESTS)
  add_test(NAME audit_protocol_frames_file
           COMMAND ${CMAKE_COMMAND} -E env STEADYSTEP_AUDIT_FRAMES=${STEADYSTEP_AUDIT_PROGRAMS_DIR}/frames.txt
                   $<TARGET_FILE:steadystep_audit_protocol_cxx> --profile uniform:15:45 --seed 3 --duration 1.2
                   --policy fixed)
  set_tests_properties(audit_protocol_frames_file PROPERTIES PASS_REGULAR_EXPRESSION
                       "^t_s,frame_s\n0,0\n0\.25,0\.25\n0\.75,0\.5\n1,0\.25\n1\.2,0\.19[0-9]*\n$")
  add_test(NAME audit_protocol_fixed COMMAND steadystep_audit_protocol_cxx --profile fixed:4 --duration 0.5)
  set_tests_properties(audit_protocol_fixed PROPERTIES PASS_REGULAR_EXPRESSION "^t_s,frame_s\n0,0\n0\.25,0\.25\n0\.5,0\.25\n$")
  add_test(NAME audit_protocol_random_refused
           COMMAND sh -c "\"$1\" --profile uniform:15:45 2>&1; echo exit $?" sh $<TARGET_FILE:steadystep_audit_protocol_cxx>)
  set_tests_properties(audit_protocol_random_refused PROPERTIES PASS_REGULAR_EXPRESSION
                       "protocol_cxx: --profile uniform:15:45: without the lab[^\n]*STEADYSTEP_AUDIT_FRAMES[^\n]*\nexit 2\n")
endif()
