# ament_lint_auto_find_test_dependencies(): find_package() every <test_depend> of the
# package quietly; each linter found registers an "ament_lint_auto" extension, and those
# run (adding one test per linter) when ament_package() calls the package hook.
macro(ament_lint_auto_find_test_dependencies)
  if(NOT "${ARGN}" STREQUAL "")
    message(FATAL_ERROR
      "ament_lint_auto_find_test_dependencies() takes no arguments, got: ${ARGN}")
  endif()
  if(NOT _AMENT_PACKAGE_NAME)
    ament_package_xml()
  endif()
  foreach(_lint_auto_dep ${${PROJECT_NAME}_TEST_DEPENDS})
    find_package(${_lint_auto_dep} QUIET)
    if(${_lint_auto_dep}_FOUND)
      list(APPEND ${PROJECT_NAME}_FOUND_TEST_DEPENDS ${_lint_auto_dep})
    endif()
  endforeach()
endmacro()
