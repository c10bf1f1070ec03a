// steadystep/audit/protocol.h from C++, with nothing but the installed core: the frame clock alone (no world), one
// row a frame of the frame's length, so that ctest can hold the frames it reads (from STEADYSTEP_AUDIT_FRAMES, or
// fixed:FPS) against what it was given.
#include <steadystep/audit/protocol.h>

int main(int argc, char** argv) {
  ssAuditRun run;
  int parsed = ssAuditRun_Parse("protocol_cxx", argc, argv, &run);
  if (parsed != 0) return parsed < 0 ? 0 : parsed;
  ssStepping stepping = ssDefaultStepping();
  if (ssAuditRun_Stepping(&run, 1.0 / 60, &stepping) != 0) {
    ssAuditRun_Finish(&run);
    return 2;
  }
  ssAuditRun_Header(&run, "t_s,frame_s", 0);
  double values[1] = {0};
  ssAuditRun_Row(&run, 0, 1, values, nullptr);
  for (double t = 0; ssAuditRun_Running(&run, t);) {
    values[0] = ssAuditRun_NextFrame(&run, t);
    t += values[0];
    ssAuditRun_OwnRow(&run, t, 1, values, 1);
  }
  ssAuditRun_Finish(&run);
  return 0;
}
