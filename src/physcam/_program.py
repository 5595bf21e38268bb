"""Whether this process is the ``physcam`` program: set by :func:`physcam.cli.run`, never by the library.

A module of its own (nothing imported) so that the program can say so at start without importing
what reads it (:mod:`physcam.figures`, which a report never needs: issue 43's start-up).
"""

RUNNING = False
