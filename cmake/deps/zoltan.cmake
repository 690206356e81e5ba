# Zoltan from Debian's libtrilinos-zoltan-dev; its TriBITS config drags in all
# of Trilinos, so the header and library are found directly.
find_path(ZOLTAN_INCLUDE_DIR zoltan.h PATH_SUFFIXES trilinos REQUIRED)
find_library(ZOLTAN_LIBRARY NAMES trilinos_zoltan zoltan REQUIRED)
add_library(shatter_dep_zoltan INTERFACE)
target_include_directories(shatter_dep_zoltan SYSTEM INTERFACE ${ZOLTAN_INCLUDE_DIR})
target_link_libraries(shatter_dep_zoltan INTERFACE ${ZOLTAN_LIBRARY} MPI::MPI_C)
add_library(Zoltan::zoltan ALIAS shatter_dep_zoltan)
