// Joint behaviour: limits, motors, welds, distance limits, collision, sleeping, determinism.
#include <gtest/gtest.h>
