// Test support: the article's oscillator in real ODE (one body on a slider whose stop lo = hi = 0 is the spring),
// driven by the stepper, recording x and v after every physics step; and the independent truths it is held to.
#ifndef STEADYSTEP_TESTS_OSCILLATOR_RIG_H
#define STEADYSTEP_TESTS_OSCILLATOR_RIG_H

#include <cmath>
#include <vector>

#include <ode/ode.h>

#include "test_stepping.h"
#include "steadystep/lab/profile.h"
#include "steadystep/steadystep.h"

struct OscillatorRig {
  double mass = 1.0, x0 = 0.5, gravity = 0.0;
  bool declare_load = false;  // tell the registry the weight the stop carries (ssRegistry_SetJointLoad)
  ssSpring spring = {40.0, 1.0};
  ssStepperDef def = TestStepperDef();

  dWorldID world = nullptr;
  dBodyID body = nullptr;
  dJointID slider = nullptr;
  ssRegistry* registry = nullptr;
  ssStepper* stepper = nullptr;
  std::vector<double> t, x, v, h;

  // Builds the world; returns the status of binding and of making the stepper.
  ssStatus Build() {
    world = dWorldCreate();
    dWorldSetGravity(world, -gravity, 0, 0);
    body = dBodyCreate(world);
    dMass m;
    dMassSetBoxTotal(&m, mass, 0.1, 0.1, 0.1);
    dBodySetMass(body, &m);
    slider = dJointCreateSlider(world, 0);
    dJointAttach(slider, body, 0);
    dJointSetSliderAxis(slider, 1, 0, 0);
    dJointSetSliderParam(slider, dParamLoStop, 0);
    dJointSetSliderParam(slider, dParamHiStop, 0);
    dBodySetPosition(body, x0, 0, 0);  // after attaching, so the slider reads x0
    registry = ssRegistry_Create(world);
    ssStatus status = ssRegistry_BindJoint(registry, slider, SS_PARAM_STOP, 1, spring, mass);
    if (status == SS_OK && declare_load)
      status = ssRegistry_SetJointLoad(registry, slider, SS_PARAM_STOP, 1, -mass * gravity);
    if (status != SS_OK) return status;
    def.world = world;
    def.registry = registry;
    def.step_done = [](void* context, double step_s) {
      auto* rig = static_cast<OscillatorRig*>(context);
      rig->h.push_back(step_s);
      rig->t.push_back((rig->t.empty() ? 0.0 : rig->t.back()) + step_s);
      rig->x.push_back(dJointGetSliderPosition(rig->slider));
      rig->v.push_back(dJointGetSliderPositionRate(rig->slider));
    };
    def.step_done_context = this;
    return ssStepper_Create(&def, &stepper);
  }

  // Runs frames from the profile until seconds of simulated time.
  ssStatus Run(const char* profile_spec, double seconds, uint64_t seed = 0) {
    ssProfile* profile = nullptr;
    ssStatus status = ssProfile_Create(profile_spec, seed, &profile);
    if (status != SS_OK) return status;
    double time = 0;
    while (status == SS_OK && time < seconds - 1e-12) {
      double frame_s = std::fmin(ssProfile_Next(profile), seconds - time);
      ssFrameReport report;
      status = ssStepper_Step(stepper, frame_s, &report);
      time += report.simulated_s;
    }
    ssProfile_Destroy(profile);
    return status;
  }

  ~OscillatorRig() {
    ssStepper_Destroy(stepper);
    ssRegistry_Destroy(registry);
    if (world) dWorldDestroy(world);
  }
};

// One step of the article's implicit-Euler recurrence, m(v'-v)/h = -k(x + h v') - c v' - m g, x' = x + h v', for a
// row of mass (kg, or kg·m² with an angular spring).
inline void ImplicitEulerStep(double mass, ssSpring spring, double gravity, double h, double* x, double* v) {
  const double k = spring.stiffness, c = spring.damping;
  *v = (mass * *v - h * k * *x - h * mass * gravity) / (mass + h * c + h * h * k);
  *x += h * *v;
}

// The recurrence over the given step lengths from rest at x0: the x after each step.
inline std::vector<double> ImplicitEuler(const OscillatorRig& rig, const std::vector<double>& steps) {
  std::vector<double> xs;
  double x = rig.x0, v = 0;
  for (double h : steps) {
    ImplicitEulerStep(rig.mass, rig.spring, rig.gravity, h, &x, &v);
    xs.push_back(x);
  }
  return xs;
}

// The exact motion of m x'' + c x' + k x = -m g from rest at x0 (under-damped), at time t.
inline double ExactPosition(const OscillatorRig& rig, double t) {
  double m = rig.mass, k = rig.spring.stiffness, c = rig.spring.damping;
  double rest = -m * rig.gravity / k, sigma = c / (2 * m), omega = std::sqrt(k / m - sigma * sigma);
  double a = rig.x0 - rest;
  return rest + std::exp(-sigma * t) * (a * std::cos(omega * t) + sigma * a / omega * std::sin(omega * t));
}

// The largest |difference| between two equally long series.
inline double MaxDifference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = a.size() == b.size() ? 0 : INFINITY;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) worst = std::fmax(worst, std::fabs(a[i] - b[i]));
  return worst;
}

#endif
