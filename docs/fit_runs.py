"""What the benchmark scripts in docs/ read back from a `friction-node fit` run.

A run NAME in OUT leaves OUT/NAME.md (the summary on stdout), OUT/NAME.log
(stderr) and OUT/NAME.wall (the wall time in s, from `timed` in
docs/bench-lib.sh). `Run(out, name)` reads them: the models table's rows by
model, what `--fit auto` chose, the held-out RMS line, the verdict, and the
last line of the log when the run failed.
"""
import re

_MODEL_ROW = re.compile(r"^\| (friction-node|Coulomb|Stribeck|LuGre)")


class Run:
    def __init__(self, out, name):
        self.name = name
        self.md = open(f"{out}/{name}.md").read()
        self.wall = open(f"{out}/{name}.wall").read().strip()
        self._log = f"{out}/{name}.log"
        # The models table, in its order: model → its cells (model, parameters,
        # …, training RMS [4], CV RMS [5], held-out RMS [6], held-out / friction [7]).
        self.rows = {}
        for line in self.md.splitlines():
            if _MODEL_ROW.match(line):
                cells = [x.strip() for x in line.strip("|").split("|")]
                self.rows[cells[0]] = cells

    def _line(self, pattern):
        m = re.search(pattern, self.md, re.M)
        return m.group(1) if m else None

    @property
    def ours(self):
        return self.rows.get("friction-node")

    @property
    def chosen(self):
        """The terms `--fit auto` chose, or None."""
        return self._line(r"^Chosen: (.*?)\. Stopped")

    @property
    def held_out(self):
        """The summary's `held-out RMS` (the `--holdout` part), or None."""
        return self._line(r"^held-out RMS ([0-9.e+-]+)")

    @property
    def verdict(self):
        return self._line(r"^(\*\*Verdict.*)$")

    def failure(self):
        """The last line of the run's log: why it printed no table."""
        lines = open(self._log).read().strip().splitlines()
        return lines[-1] if lines else "?"
