#!/usr/bin/python3
# moved to tools/scripts/ensemble.py; this stub keeps the old spelling working
import os
import sys

script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scripts", "ensemble.py")
os.execv(sys.executable, [sys.executable, script] + sys.argv[1:])
