"""How every tool answers --help, the argparse way (rostopic, roslaunch and pytest are the
models): the program named as the user types it (`scripts/evaluate.sh`, `python -m
m2wr_tools.bench.series_runs`), the tool's own text as written (a colon does not cut it, a
table keeps its columns), every option with a sentence and its default in one style,
`(default: X)`, then examples and the exit statuses.

    parser = usage.parser("scripts/evaluate.sh", __doc__, examples=[...])

The module docstring is the description, less its synopsis lines (the indented lines that
start with the program's name: argparse prints its own usage line) and less its "Exit
status" paragraph, which goes last, after the examples.
"""
import argparse

EXIT_STATUSES = ("Exit status: 0 on success; 1 when it could not run (the message says why); "
                 "2 for bad arguments; 130 when interrupted.")


class HelpFormatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Description and epilog as written; `(default: X)` after every option's help, except
    where the help says its default itself (`(default: one per core)`), or where there is
    nothing to say (a flag off by default, no value)."""

    def _get_help_string(self, action):
        text = action.help or ""
        nothing = (action.default is None or action.default is False
                   or action.default is argparse.SUPPRESS or action.default in ([], ()))
        if "(default" in text or nothing:
            return text
        return super()._get_help_string(action)


def _is_synopsis(paragraph, prog):
    lines = [line for line in paragraph.splitlines() if line.strip()]
    return bool(lines) and lines[0].startswith("  ") and lines[0].strip().startswith(prog)


def split_doc(doc, prog):
    """(description, exit statuses) from a tool's module docstring."""
    paragraphs = [p.rstrip() for p in (doc or "").strip("\n").split("\n\n")]
    kept, statuses = [], ""
    for paragraph in paragraphs:
        if _is_synopsis(paragraph, prog):
            if kept and kept[-1].endswith(":"):
                kept[-1] = kept[-1][:-1] + "."
            continue
        if paragraph.startswith("Exit status"):
            statuses = paragraph
            continue
        kept.append(paragraph)
    return "\n\n".join(kept), statuses


def parser(prog, doc, examples=(), exit_statuses=None, **kwargs):
    """An ArgumentParser that follows the convention above. `examples`: command lines (with
    an optional `   # what it does`) printed under "examples:"."""
    description, statuses = split_doc(doc, prog)
    epilog = []
    if examples:
        epilog.append("examples:\n" + "\n".join("  " + line for line in examples))
    epilog.append(exit_statuses or statuses or EXIT_STATUSES)
    return argparse.ArgumentParser(prog=prog, description=description,
                                   epilog="\n\n".join(epilog), formatter_class=HelpFormatter,
                                   **kwargs)
