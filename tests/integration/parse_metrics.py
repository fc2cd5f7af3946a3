#!/usr/bin/python3
"""Parses a /metrics answer (file given as the argument) with Prometheus' own text-format
parser and prints one line per family: name, type, number of samples. Exits 1 when the text
does not parse, so the C++ test that calls it sees the parser's error."""
import sys

from prometheus_client.parser import text_string_to_metric_families

try:
    with open(sys.argv[1], encoding="utf-8") as text:
        for family in text_string_to_metric_families(text.read()):
            print(family.name, family.type, len(family.samples))
except Exception as error:  # the parser raises ValueError and others; report any
    print(f"parse error: {error}", file=sys.stderr)
    sys.exit(1)
