# Debian's parallel HDF5 (libhdf5-openmpi-dev).
set(HDF5_PREFER_PARALLEL ON)
find_package(HDF5 REQUIRED COMPONENTS C)
if(NOT HDF5_IS_PARALLEL)
  message(FATAL_ERROR "shatter needs a parallel HDF5 (apt-get install libhdf5-openmpi-dev)")
endif()
