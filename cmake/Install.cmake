# `cmake --install`: headers, the static libraries, the CLI, the trained models and a package
# configuration, so that another project can say find_package(kartograf) and link kartograf::outputs
# (everything) or a lower layer (kartograf::algorithms: core, compute and the algorithms on Eigen).
include(CMakePackageConfigHelpers)

set(KARTOGRAF_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/kartograf)
set(KARTOGRAF_LAYERS core compute geometry segmentation registration mapping eval synth rooms_scan
    algorithms rooms semantic features formats pipeline outputs)
foreach(library ${KARTOGRAF_LAYERS})
  set_target_properties(kartograf_${library} PROPERTIES EXPORT_NAME ${library})
  add_library(kartograf::${library} ALIAS kartograf_${library})
endforeach()
list(TRANSFORM KARTOGRAF_LAYERS PREPEND kartograf_ OUTPUT_VARIABLE kartograf_layer_targets)
install(TARGETS ${kartograf_layer_targets}
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
