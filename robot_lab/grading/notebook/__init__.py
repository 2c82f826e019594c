"""Notebook grading: a student's notebook run in a kernel, its check cells scored.

`grade` (one submission), `batch` (a class: `grade_many`, the gradebook's rows) and
`answer_key` (the instructor's copy: which exercise a notebook is, its locked cells, the
checks judged by a token).
"""
