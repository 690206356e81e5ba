#pragma once
// MPI for a whole GoogleTest program (gtest_main has no MPI_Init): include
// once in a test file of a program that needs MPI.
#include <gtest/gtest.h>
#include <mpi.h>

namespace shatter::test {

class MpiEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  }
  void TearDown() override { MPI_Finalize(); }
};

[[maybe_unused]] inline ::testing::Environment* const mpi_environment =
    ::testing::AddGlobalTestEnvironment(new MpiEnvironment);

}  // namespace shatter::test
