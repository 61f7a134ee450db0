"""Generated blocks of the docs: the text between `<!-- BEGIN GENERATED: SCRIPT -->` and
`<!-- END GENERATED -->` in a Markdown file, which only SCRIPT writes.

A block may carry a `<!-- headline: KEY=VALUE ... -->` line: the figures `scripts/headline.py`
copies into the README's headline block (and `cargo test --test it repository` checks there).
Writing such a block rewrites the README's headline block as well.
"""
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
END = "<!-- END GENERATED -->"


def begin(script):
    return f"<!-- BEGIN GENERATED: {script} -->"


def replace(path, script, text):
    """Replaces the block that `script` (e.g. "scripts/plan_bench.py") owns in `path` by `text`."""
    path = pathlib.Path(path)
    doc = path.read_text()
    start = doc.index(begin(script)) + len(begin(script))
    end = doc.index(END, start)
    path.write_text(doc[:start] + "\n" + text.rstrip("\n") + "\n" + doc[end:])
    # A block with a headline line feeds the README's headline block: rewrite that too, so the
    # two cannot be committed apart.
    if "<!-- headline:" in text and script != "scripts/headline.py":
        import headline  # noqa: E402 (headline imports this module)
        replace(ROOT / "README.md", headline.SCRIPT, headline.block())
        print("README.md: headline block rewritten (scripts/headline.py)", file=sys.stderr)


def block(path, script):
    """The text of the block `script` owns in `path`."""
    doc = pathlib.Path(path).read_text()
    start = doc.index(begin(script)) + len(begin(script))
    return doc[start:doc.index(END, start)]


def headline(path, script):
    """The KEY=VALUE pairs of the block's `<!-- headline: ... -->` line, as strings."""
    for line in block(path, script).splitlines():
        if line.startswith("<!-- headline:") and line.endswith("-->"):
            pairs = line[len("<!-- headline:"):-len("-->")].split()
            return dict(p.split("=", 1) for p in pairs)
    raise ValueError(f"{path}: the block of {script} has no headline line")


def headline_line(**figures):
    return "<!-- headline: " + " ".join(f"{k}={v}" for k, v in figures.items()) + " -->"


def revision():
    """The commit the code is at, with `-dirty` if a tracked file other than a Markdown one (which
    the generated blocks themselves change) differs from it; "unknown" without git."""
    try:
        def git(*args):
            return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True,
                                  check=True).stdout
        head = git("rev-parse", "--short", "HEAD").strip()
        changed = [l[3:] for l in git("status", "--porcelain", "--untracked-files=no").splitlines()]
        return head + ("-dirty" if any(not c.endswith(".md") for c in changed) else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
