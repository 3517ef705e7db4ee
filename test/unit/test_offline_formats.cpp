#include <gtest/gtest.h>
TEST(OfflineFormats, Placeholder) {}
