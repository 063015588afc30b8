"""Running a session: the live engine (source → session → scheduler → bridges), the per-file offline run of
``generate``, and building both from command-line flags.
"""
