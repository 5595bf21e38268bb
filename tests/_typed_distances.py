"""Distances typed with typographic feet and inch marks, and their millimetres worked by hand from the
international foot and inch (1 in = 25.4 mm exactly, 1 ft = 12 in): 10 ft 6 in = 126 in = 3200.4 mm; 20 ft =
6096 mm; 6 in = 152.4 mm; 9 ft 10 1/8 in = 118.125 in = 3000.375 mm; 1 ft 2 in = 14 in = 355.6 mm. Shared by
the parser's tests (tests/test_units_typographic_marks.py) and the page's (tests/serve/test_onset_js.py)."""

#: (as typed, mm by hand)
TYPED = [
    ("10’6”", 3200.4),  # iPhone: right single and right double quotation marks
    ("10′6″", 3200.4),  # primes
    ("10’ 6”", 3200.4),
    ("10‘6“", 3200.4),  # left quotation marks, as a keyboard types them after a space or at the start
    ("10' 6”", 3200.4),  # mixed
    ("20’", 6096.0),
    ("6”", 152.4),
    ("6″", 152.4),
    ("6’’", 152.4),  # two foot marks are an inch mark (the typewriter's double prime)
    ("6''", 152.4),
    ("10'6''", 3200.4),
    ("10′6′′", 3200.4),
    ("9’ 10 1/8”", 3000.375),
    ("-1’ 2”", -355.6),
]
