# examples/audit_pendulum.c, which takes part in `steadystep audit` through lab/include/steadystep/lab/audit_flags.h
# (docs/audit.md), included from CMakeLists.txt: the protocol's header and t = 0 row with the count columns, one row
# per frame whatever the policy (fixed:30 for 0.1 s: t = 0.0333... next), its own stepping without --policy, and a
# bad flag or policy refused with exit 2, naming it.
add_test(NAME example_audit_pendulum_csv
         COMMAND steadystep_example_audit_pendulum --policy exact --profile fixed:30 --duration 0.1)
set_tests_properties(example_audit_pendulum_csv PROPERTIES PASS_REGULAR_EXPRESSION
                     "^t_s,tip_x_m,tip_z_m,steps,rows_by_mapping,[^\n]+\n0,[^\n]+,0,0,0,0,0,0,0\n0\\.0333[^\n]*,2,")
add_test(NAME example_audit_pendulum_own
         COMMAND steadystep_example_audit_pendulum --profile fixed:30 --duration 0.1)
set_tests_properties(example_audit_pendulum_own PROPERTIES PASS_REGULAR_EXPRESSION
                     "\n0\\.0333[^\n]*,1,-1,-1,-1,-1,-1,-1\n")
foreach(bad "--policy sideways" "--duration 0" "--seed 1.5" "--profile uniform:45:15" "--frames 3")
  string(REPLACE " " ";" words "${bad}")
  string(MAKE_C_IDENTIFIER "${bad}" name)
  list(GET words 0 flag)
  add_test(NAME example_audit_pendulum_bad${name}
           COMMAND sh -c "\"$1\" \"$2\" \"$3\" 2>&1; echo exit $?" sh $<TARGET_FILE:steadystep_example_audit_pendulum>
                   ${words})
  set_tests_properties(example_audit_pendulum_bad${name} PROPERTIES PASS_REGULAR_EXPRESSION
                       "audit_pendulum: ${flag} [^\n]*\nexit 2\n")
endforeach()
