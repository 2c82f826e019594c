# Run by ament_package(): every linter's registered hook adds its test.
ament_execute_extensions(ament_lint_auto EXCLUDE "${AMENT_LINT_AUTO_EXCLUDE}")
