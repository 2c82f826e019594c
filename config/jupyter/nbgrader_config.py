"""nbgrader in the course's Lab: Validate fails when a cell runs past its timeout.

nbgrader's Execute interrupts such a cell and goes on, and Validate counts only graded
cells: a hang anywhere else ended in "Success! Your notebook passes all the tests."
Without the interrupt, nbclient raises CellTimeoutError and Validate reports the cell
that hung. Only Validate: autograde still interrupts and goes on, so one hung cell costs a
submission that cell's points, not the rest. The kit's server config puts this folder on
JUPYTER_CONFIG_PATH, where the Validate handler looks (tests/test_validate_timeout.py).
"""

c = get_config()  # type: ignore[name-defined]  # noqa: F821 (nbgrader's config loader)

c.Validator.Execute.interrupt_on_timeout = False
