/* steadystep: SS_API, the mark of every function the library exports.
 *
 * The library is compiled with hidden visibility, so only the functions of its public headers (marked SS_API)
 * are part of its ABI. Three cases:
 *  - building the shared library (SS_BUILDING_LIBRARY): the marked functions are exported;
 *  - a static library (SS_STATIC, defined by the CMake target and the pkg-config file of a static build): no mark,
 *    so the functions stay hidden in whatever shared object a program links them into;
 *  - a program using the shared library: nothing on ELF; imported on Windows.
 */
#ifndef STEADYSTEP_EXPORT_H
#define STEADYSTEP_EXPORT_H

#if defined(SS_STATIC)
#define SS_API
#elif defined(_WIN32)
#if defined(SS_BUILDING_LIBRARY)
#define SS_API __declspec(dllexport)
#else
#define SS_API __declspec(dllimport)
#endif
#elif defined(__GNUC__)
#define SS_API __attribute__((visibility("default")))
#else
#define SS_API
#endif

#endif
