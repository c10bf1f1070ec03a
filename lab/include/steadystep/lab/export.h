/* steadystep lab: SS_LAB_API, the mark of every function the lab library exports.
 *
 * The lab is one shared library that holds the core and the lab (what the tests, the benchmarks, the examples and
 * the Python package load), compiled with hidden visibility like the core: it exports the core's API (SS_API) and
 * the lab's (SS_LAB_API), and neither the core's internals (ssFail, ssCheck*) nor the scenes' own (ssBoxes*,
 * ssRng*). The lab is never installed for C programs, so there is no static or import case.
 */
#ifndef STEADYSTEP_LAB_EXPORT_H
#define STEADYSTEP_LAB_EXPORT_H

#if defined(__GNUC__)
#define SS_LAB_API __attribute__((visibility("default")))
#else
#define SS_LAB_API
#endif

#endif
