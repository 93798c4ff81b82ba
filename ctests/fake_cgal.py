#!/usr/bin/env python3
"""A stand-in for cgal_delaunay that reports a wrong triangulation (1 tet, checksum 0).

Used by the ctest `compare_detects_mismatch` to show that compare_delaunay.py fails when the two
triangulations differ."""
import json
import sys

n = 0
with open(sys.argv[1]) as f:
    for line in f:
        if line.split("#", 1)[0].strip():
            n += 1
print(json.dumps({"n_points": n, "n_vertices": n, "n_tets": 1, "seconds": 1.0,
                  "peak_rss_mb": 1.0, "bytes_per_tet": 1e6, "tets_checksum": "0000000000000000"}))
