# Loaded by find_package(ament_lint_auto): the macro, and the hook ament_package() runs.
if(_${PROJECT_NAME}_AMENT_PACKAGE)
  message(FATAL_ERROR "find_package(ament_lint_auto) must come before ament_package()")
endif()

find_package(ament_cmake_core QUIET REQUIRED)
find_package(ament_cmake_test QUIET REQUIRED)

include("${ament_lint_auto_DIR}/ament_lint_auto_find_test_dependencies.cmake")
ament_register_extension("ament_package" "ament_lint_auto" "ament_lint_auto_package_hook.cmake")
