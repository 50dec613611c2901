#pragma once
/// @file
/// REDRES_HOT marks a function of the per-step path (the controller's step, the scheme's build, the plugins'
/// contributions, the kinematics, the engines' iterations). GCC and clang place such functions in `.text.hot`, next
/// to each other: the step's code then fills few instruction-cache lines, instead of sharing them with code that runs
/// once. The step's code is about the size of a 32 KB L1 instruction cache, so its layout shows in the step's time
/// (docs/performance.md).

#if defined(__GNUC__)
#define REDRES_HOT __attribute__((hot))
#else
#define REDRES_HOT
#endif
