# `cmake --install`: headers, the static libraries, the CLI, the trained models and a package
# configuration, so that another project can say find_package(kartograf) and link kartograf::io
# (everything) or a lower layer (kartograf::compute: core, compute and the algorithms on Eigen).
include(CMakePackageConfigHelpers)

set(KARTOGRAF_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/kartograf)
foreach(library compute rooms semantic pipeline io)
  set_target_properties(kartograf_${library} PROPERTIES EXPORT_NAME ${library})
  add_library(kartograf::${library} ALIAS kartograf_${library})
endforeach()
install(TARGETS kartograf_compute kartograf_rooms kartograf_semantic kartograf_pipeline kartograf_io
        EXPORT kartografTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS kartograf RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/kartograf DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/models/ DESTINATION ${CMAKE_INSTALL_DATADIR}/kartograf/models
        FILES_MATCHING PATTERN "*.yml.gz")
install(EXPORT kartografTargets NAMESPACE kartograf:: DESTINATION ${KARTOGRAF_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/kartografConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/kartografConfig.cmake
                              INSTALL_DESTINATION ${KARTOGRAF_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/kartografConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/kartografConfig.cmake
              ${PROJECT_BINARY_DIR}/kartografConfigVersion.cmake
        DESTINATION ${KARTOGRAF_CMAKE_DIR})
