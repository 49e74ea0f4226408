# Install rules and the CMake package (find_package(tippe)): libraries, curated headers, config, tippe.pc.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Installed headers, all under include/tippe/ in the source tree's layout:
#   tippe/tippe.h             the entry point of tippe::core (self-contained: no harness header is
#                             installed, so harness files can move without changing the installed tree);
#   tippe/analytic/*.h        the reference model (tippe::analytic), as in analytic/;
#   tippe/engines/core/*.h    the simulator interface and adapter factories (tippe::engines), as in
#                             engines/core/.
# Project headers include each other by their path from the repository root ("analytic/scene.h"),
# so include/tippe/ is the consumer's include directory for them, as the root is in the build;
# include/ is the one for <tippe/tippe.h>.
set(TIPPE_INSTALLED_ENGINE_HEADERS engines/core/simulator.h engines/core/adapters.h)

set(TIPPE_LIBRARY_TARGETS tippe_analytic tippe_engines tippe_core)
set_target_properties(tippe_analytic PROPERTIES EXPORT_NAME analytic)
set_target_properties(tippe_engines PROPERTIES EXPORT_NAME engines)
set_target_properties(tippe_core PROPERTIES EXPORT_NAME core)
# The source tree's root is the build's include directory; it holds for the build tree only.
# Installed, every target's headers are found from include/ (<tippe/tippe.h>) and include/tippe/
# (the root-relative includes inside the installed headers).
foreach(t ${TIPPE_LIBRARY_TARGETS})
  get_target_property(dirs ${t} INTERFACE_INCLUDE_DIRECTORIES)
  if(NOT dirs)
    set(dirs "")
  endif()
  set(wrapped "")
  foreach(d ${dirs})
    if(d MATCHES "^\\$<")
      list(APPEND wrapped "${d}")
    else()
      list(APPEND wrapped "$<BUILD_INTERFACE:${d}>")
    endif()
  endforeach()
  list(APPEND wrapped "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>" "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/tippe>")
  set_target_properties(${t} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${wrapped}")
endforeach()

install(TARGETS ${TIPPE_LIBRARY_TARGETS} EXPORT tippeTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
if(TARGET tippe)
  install(TARGETS tippe RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
if(TARGET tippe_mpi)
  # Opened by tippe under an MPI launcher, from lib/tippe/ beside the runtime (harness/sweep/mpi_session.cpp).
  install(TARGETS tippe_mpi LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/tippe)
endif()
# Engines as modules (TIPPE_ENGINE_MODULES): the shared runtime in lib/, each module in
# lib/tippe/engines/ (where the registry looks, beside the runtime), and the programs that load
# them find the runtime from their own place.
if(TARGET tippe_runtime)
  install(TARGETS tippe_runtime LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  get_property(_modules GLOBAL PROPERTY TIPPE_ENGINE_MODULE_TARGETS)
  install(TARGETS ${_modules} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/tippe/engines)
  file(RELATIVE_PATH _bin_to_lib /${CMAKE_INSTALL_BINDIR} /${CMAKE_INSTALL_LIBDIR})
  if(TARGET tippe)
    set_target_properties(tippe PROPERTIES INSTALL_RPATH "$ORIGIN/${_bin_to_lib}")
  endif()
  if(TARGET tippe_python)
    # The module is in the package directory tippe/ under the Python install directory.
    file(RELATIVE_PATH _py_to_lib /${TIPPE_PYTHON_INSTALL_DIR}/tippe /${CMAKE_INSTALL_LIBDIR})
    set_target_properties(tippe_python PROPERTIES INSTALL_RPATH "$ORIGIN/${_py_to_lib}")
  endif()
endif()
# Whether the installed static tippe::engines holds the engines (TIPPE_ENGINE_MODULES=OFF) or the
# reference alone: what the package's config and tippe.pc ask a consumer to find and link.
if(TIPPE_ENGINES AND NOT TIPPE_ENGINE_MODULES)
  set(TIPPE_STATIC_ENGINES ON)
else()
  set(TIPPE_STATIC_ENGINES OFF)
endif()
install(FILES ${PROJECT_SOURCE_DIR}/include/tippe/tippe.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tippe)
file(GLOB TIPPE_ANALYTIC_HEADERS ${PROJECT_SOURCE_DIR}/analytic/*.h)
install(FILES ${TIPPE_ANALYTIC_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tippe/analytic)
foreach(h ${TIPPE_INSTALLED_ENGINE_HEADERS})
  get_filename_component(dir ${h} DIRECTORY)
  install(FILES ${PROJECT_SOURCE_DIR}/${h} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tippe/${dir})
endforeach()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/schemas/ DESTINATION ${CMAKE_INSTALL_DATADIR}/tippe/schemas)

set(TIPPE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/tippe)
install(EXPORT tippeTargets NAMESPACE tippe:: DESTINATION ${TIPPE_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/tippeConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/tippeConfig.cmake INSTALL_DESTINATION ${TIPPE_CMAKE_DIR})
# 0.x: a minor version may change the interface.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/tippeConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/tippeConfig.cmake ${PROJECT_BINARY_DIR}/tippeConfigVersion.cmake
        DESTINATION ${TIPPE_CMAKE_DIR})

# pkg-config: the libraries are static, so their dependencies are listed for the link line too.
if(TIPPE_STATIC_ENGINES)
  set(TIPPE_PC_REQUIRES "eigen3 tomlplusplus nlohmann_json bullet-float64 ode")
  # DART links as its imported target `dart` (libdart and its FCL); the .pc names them directly.
  # Simbody (engines/simbody/) likewise: its three libraries, no .pc of its own in Debian; and
  # Siconos (engines/siconos/): its kernel and numerics.
  set(TIPPE_PC_LIBS "-lmujoco -ldart -lfcl -lSimTKsimbody -lSimTKmath -lSimTKcommon -lsiconos_kernel -lsiconos_numerics")
else()
  set(TIPPE_PC_REQUIRES "eigen3 tomlplusplus nlohmann_json")
  set(TIPPE_PC_LIBS "")
endif()
# The prefix is found from the .pc file's own place, so `cmake --install --prefix DIR` works too.
file(RELATIVE_PATH TIPPE_PC_TO_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
configure_file(${PROJECT_SOURCE_DIR}/cmake/tippe.pc.in ${PROJECT_BINARY_DIR}/tippe.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/tippe.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
