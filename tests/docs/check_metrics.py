#!/usr/bin/env python3
"""Every metric the recorder's /metrics can export (the names in
recorder/status/prometheus_metrics.cpp) is in docs/web-interface.md's
metrics section, and every one documented there exists.

    check_metrics.py SOURCE_DIR
"""
import pathlib
import re
import sys

source = pathlib.Path(sys.argv[1])
exported = set(re.findall(r'"(wircam_[a-z_]+)',
                          (source / "recorder/status/prometheus_metrics.cpp").read_text()))
page = (source / "docs/web-interface.md").read_text()
documented = set(re.findall(r"`(wircam_[a-z_]+)", page)) - {"wircam_token"}
problems = [f"exported but not in docs/web-interface.md: {name}"
            for name in sorted(exported - documented)]
problems += [f"in docs/web-interface.md but never exported: {name}"
             for name in sorted(documented - exported)]
if not exported:
    problems.append("no metric found in prometheus_metrics.cpp: the check reads the wrong file")
print("\n".join(problems) or f"{len(exported)} metrics, each documented")
sys.exit(1 if problems else 0)
