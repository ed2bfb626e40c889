# Zoltan (Debian: libtrilinos-zoltan-dev) as the imported target Zoltan::Zoltan.  Found directly
# rather than through Trilinos' ZoltanConfig.cmake, whose target lists the PT-Scotch development
# symlinks (libptscotch.so) that the Debian package does not install; the shared library finds its
# own dependencies at run time.
find_path(Zoltan_INCLUDE_DIR zoltan.h PATH_SUFFIXES trilinos)
find_library(Zoltan_LIBRARY NAMES trilinos_zoltan zoltan)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Zoltan REQUIRED_VARS Zoltan_LIBRARY Zoltan_INCLUDE_DIR)
if(Zoltan_FOUND AND NOT TARGET Zoltan::Zoltan)
  add_library(Zoltan::Zoltan UNKNOWN IMPORTED)
  set_target_properties(Zoltan::Zoltan PROPERTIES IMPORTED_LOCATION "${Zoltan_LIBRARY}"
                                                  INTERFACE_INCLUDE_DIRECTORIES "${Zoltan_INCLUDE_DIR}")
endif()
