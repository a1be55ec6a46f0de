"""The ``tdcm`` command line: thin shells over library functions."""
