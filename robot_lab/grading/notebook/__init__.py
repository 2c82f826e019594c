"""Notebook grading: a student's notebook run in a kernel, its check cells scored.

`grade` (one submission, or a class with `grade_many`) and `answer_key` (the instructor's
copy: which exercise a notebook is, its locked cells, the checks judged by a token).
"""
