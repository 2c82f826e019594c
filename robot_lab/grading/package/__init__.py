"""Package grading: a class's ROS 2 packages built, launched, watched and scored.

`submission` (who handed in what) → `grade` (the class: one sandboxed job per student,
`sandbox`) → in the job, `job` (the stages: files, build, run) with `live` (the student's
launch under the kit's launcher, observed through `roles`) → the checks in `checks/`,
each registered by id (`registry`) and weighted by a `rubric`. `similarity` compares the
class's packages.
"""
