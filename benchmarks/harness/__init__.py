"""Harnesses of the source checkout: they drive a real ``jik serve`` with the test tools
(schemathesis's fuzzing, Playwright's browser) and need the ``test`` extra. The wheel leaves
this folder out (pyproject.toml lists the packages it ships); ``jik bench`` finds its
``bench_*.py`` beside the shipped ones."""
