"""Runs the nebula command line for the validation studies: one work folder, its own table cache."""
import json
import os
import subprocess


class Runner:
    def __init__(self, args):
        self.nebula = os.path.abspath(args.nebula)
        self.work = os.path.abspath(args.work)
        self.backend = args.backend
        self.env = dict(os.environ, NEBULA_CACHE_DIR=os.path.join(self.work, "cache"))

    def run(self, argv):
        r = subprocess.run([self.nebula] + argv, capture_output=True, text=True, env=self.env, cwd=self.work)
        if r.returncode != 0:
            raise SystemExit(f"nebula {' '.join(argv)} failed ({r.returncode}): {r.stderr.strip()}")
        return r.stdout

    def compare(self, a, b):
        """Per band: bias, its standard error, L2 beyond the truth's noise, ... (`nebula compare --json`)."""
        return json.loads(self.run(["compare", a, b, "--json"]))["bands"]
