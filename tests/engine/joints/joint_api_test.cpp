// Joint API: validation, handles.
#include <gtest/gtest.h>
