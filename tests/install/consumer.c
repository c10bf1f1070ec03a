/* A program outside the project that finds the installed library, as a user's would. */
#include <stdio.h>

#include <steadystep/steadystep.h>

int main(void) {
  ssSoftness softness;
  if (ssImplicitEulerSoftness((ssSpring){40.0, 1.0}, 1.0 / 30.0, &softness) != SS_OK) return 1;
  printf("erp %.6f cfm %.6f\n", softness.erp, softness.cfm);
  return 0;
}
