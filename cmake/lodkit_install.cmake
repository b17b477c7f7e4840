# `cmake --install` gives a CMake package: find_package(lodkit CONFIG) with
#   lodkit::engine  lod::Service over baked .lod assets (runtime + oneTBB; no OpenMesh/Embree)
#   lodkit::lodkit  everything: mesh baking, scene configs, the C API
# The static libraries' own link needs (oneTBB, Threads; OpenMesh, Embree, toml++ for the
# full library) are found again by lodkitConfig.cmake. Only include/lodkit/ is installed:
# those headers include nothing but each other and the standard library.
include(CMakePackageConfigHelpers)

set(LOD_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/lodkit CACHE STRING "Where lodkitConfig.cmake is installed")

# Two export sets so that an engine-only consumer (find_package(lodkit COMPONENTS engine))
# does not even need OpenMesh, Embree or toml++ installed.
install(TARGETS lod_runtime lod_engine EXPORT lodkitEngineTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS lod_preprocess lod_jobs EXPORT lodkitTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT lodkitEngineTargets NAMESPACE lodkit:: DESTINATION ${LOD_INSTALL_CMAKEDIR})
install(EXPORT lodkitTargets NAMESPACE lodkit:: DESTINATION ${LOD_INSTALL_CMAKEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/lodkit DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h" PATTERN "*.hpp")

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/lodkitConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/lodkitConfig.cmake INSTALL_DESTINATION ${LOD_INSTALL_CMAKEDIR})
# 0.x: a new minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/lodkitConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/lodkitConfig.cmake ${PROJECT_BINARY_DIR}/lodkitConfigVersion.cmake
        DESTINATION ${LOD_INSTALL_CMAKEDIR})
