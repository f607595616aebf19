# cmake --install build --prefix P installs:
#   P/include/contactrom/{core,fom,rom,baselines}/*.hpp   (#include <contactrom/rom/reduced_model.hpp>)
#   P/lib/libcontactrom_{core,fom,rom,baselines}.{a,so}
#   P/bin/contactrom
#   P/share/contactrom/{problems,meshes}
#   P/lib/cmake/contactrom/contactromConfig.cmake (+ version, targets)
include(CMakePackageConfigHelpers)
set(CONTACTROM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/contactrom)

# Only the public headers (contactrom_add_library's PUBLIC_HEADERS): the private ones
# include dependencies the package does not provide (HDF5) or are internals.
foreach(folder core fom rom baselines)
  get_target_property(headers contactrom_${folder} CONTACTROM_PUBLIC_HEADERS)
  install(FILES ${headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/contactrom/${folder})
endforeach()
install(TARGETS contactrom_core contactrom_fom contactrom_rom contactrom_baselines EXPORT contactromTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The installed CLI finds the shared libraries next to it (no effect when static).
set_target_properties(contactrom PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS contactrom RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${CONTACTROM_PROBLEM_DIR}/ DESTINATION ${CONTACTROM_INSTALL_DATADIR}/problems
        FILES_MATCHING PATTERN "*.toml")
install(DIRECTORY ${CONTACTROM_MESH_DIR}/ DESTINATION ${CONTACTROM_INSTALL_DATADIR}/meshes
        FILES_MATCHING PATTERN "*.geo" PATTERN "*.md")

install(EXPORT contactromTargets NAMESPACE contactrom:: DESTINATION ${CONTACTROM_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/contactromConfig.cmake.in
  ${PROJECT_BINARY_DIR}/contactromConfig.cmake
  INSTALL_DESTINATION ${CONTACTROM_CMAKE_DIR}
  PATH_VARS CONTACTROM_INSTALL_DATADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/contactromConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/contactromConfig.cmake ${PROJECT_BINARY_DIR}/contactromConfigVersion.cmake
        ${PROJECT_SOURCE_DIR}/cmake/ContactromImportedDependencies.cmake
        DESTINATION ${CONTACTROM_CMAKE_DIR})
