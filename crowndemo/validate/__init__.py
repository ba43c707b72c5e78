"""The validation suite (method.md §7-8): reference cases, error against run time, the stability
suite, crown metrics and verdicts, the regime map."""
