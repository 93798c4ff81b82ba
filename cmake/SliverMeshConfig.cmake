# CMake package for slivermesh (installed by scripts/install.sh PREFIX):
#
#   find_package(SliverMesh 0.1 CONFIG REQUIRED)      # with -DCMAKE_PREFIX_PATH=PREFIX
#   target_link_libraries(my_app PRIVATE SliverMesh::slivermesh)
#
# Imported targets:
#   SliverMesh::slivermesh_static  PREFIX/lib/libslivermesh.a, with the system libraries Rust's
#                                  standard library needs (pthread, dl, m, rt, util)
#   SliverMesh::slivermesh_shared  PREFIX/lib/libslivermesh.so
#   SliverMesh::slivermesh         the static one; the shared one if SliverMesh_USE_SHARED is ON
#                                  when find_package runs
# All carry the include directory (slivermesh.h).
#
# Variables:
#   SliverMesh_VERSION            the library version
#   SliverMesh_INCLUDE_DIR        PREFIX/include
#   SliverMesh_FORTRAN_MODULE     PREFIX/include/slivermesh.f90: the ISO_C_BINDING interface
#                                 module, shipped as source; add it to your Fortran target's
#                                 sources so your compiler builds the .mod
#
# Relocatable: paths are computed from this file's location (PREFIX/lib/cmake/SliverMesh).
# Linux only for now (the library is built by cargo for the host).

get_filename_component(_slivermesh_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

set(SliverMesh_INCLUDE_DIR "${_slivermesh_prefix}/include")
set(SliverMesh_FORTRAN_MODULE "${_slivermesh_prefix}/include/slivermesh.f90")
set(_slivermesh_static "${_slivermesh_prefix}/lib/libslivermesh.a")
set(_slivermesh_shared "${_slivermesh_prefix}/lib/libslivermesh.so")

foreach(_slivermesh_file IN ITEMS "${SliverMesh_INCLUDE_DIR}/slivermesh.h" "${_slivermesh_static}"
                                  "${_slivermesh_shared}")
  if(NOT EXISTS "${_slivermesh_file}")
    set(SliverMesh_FOUND FALSE)
    set(SliverMesh_NOT_FOUND_MESSAGE "missing ${_slivermesh_file}: reinstall with scripts/install.sh")
    return()
  endif()
endforeach()

# FindThreads needs C or C++ enabled; a Fortran-only project links pthread by name.
get_property(_slivermesh_languages GLOBAL PROPERTY ENABLED_LANGUAGES)
if("C" IN_LIST _slivermesh_languages OR "CXX" IN_LIST _slivermesh_languages)
  include(CMakeFindDependencyMacro)
  set(THREADS_PREFER_PTHREAD_FLAG ON)
  find_dependency(Threads)
  set(_slivermesh_threads Threads::Threads)
else()
  set(_slivermesh_threads pthread)
endif()

if(NOT TARGET SliverMesh::slivermesh_static)
  set(_slivermesh_system_libs ${_slivermesh_threads} ${CMAKE_DL_LIBS})
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
    list(APPEND _slivermesh_system_libs m rt util)
  endif()

  add_library(SliverMesh::slivermesh_static STATIC IMPORTED)
  set_target_properties(SliverMesh::slivermesh_static PROPERTIES
    IMPORTED_LOCATION "${_slivermesh_static}"
    IMPORTED_LINK_INTERFACE_LANGUAGES "C"
    INTERFACE_INCLUDE_DIRECTORIES "${SliverMesh_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${_slivermesh_system_libs}")

  add_library(SliverMesh::slivermesh_shared SHARED IMPORTED)
  set_target_properties(SliverMesh::slivermesh_shared PROPERTIES
    IMPORTED_LOCATION "${_slivermesh_shared}"
    # cargo sets no SONAME: link as -lslivermesh so executables record "libslivermesh.so".
    IMPORTED_NO_SONAME TRUE
    INTERFACE_INCLUDE_DIRECTORIES "${SliverMesh_INCLUDE_DIR}")

  add_library(SliverMesh::slivermesh INTERFACE IMPORTED)
  if(SliverMesh_USE_SHARED)
    set_target_properties(SliverMesh::slivermesh PROPERTIES
      INTERFACE_LINK_LIBRARIES SliverMesh::slivermesh_shared)
  else()
    set_target_properties(SliverMesh::slivermesh PROPERTIES
      INTERFACE_LINK_LIBRARIES SliverMesh::slivermesh_static)
  endif()
endif()

unset(_slivermesh_file)
unset(_slivermesh_languages)
unset(_slivermesh_threads)
unset(_slivermesh_system_libs)
unset(_slivermesh_static)
unset(_slivermesh_shared)
unset(_slivermesh_prefix)
set(SliverMesh_FOUND TRUE)
