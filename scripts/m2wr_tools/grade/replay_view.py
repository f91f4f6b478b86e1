"""Each graded run's replay in the report (the browser view of pybullet_gazebo.web): the
batch runner keeps it as <batch>/runs/<run_id>.replay.json (RunOptions.replay); the report
writes it as runs/<run_id>.html + .js beside runs/web/ (the page's files and three.js), so
the report stays a folder that opens from disk with no network, and each student page
embeds its runs' replays next to their pictures."""
import html
import os

from pybullet_gazebo.web import site

HEIGHT = 360                    # [px] of an embedded replay


def write_replays(output, records):
    """Writes the replay page of each record that has one; returns {run_id: page name}."""
    pages = {}
    for record in records:
        path = record.get("replay")
        if not path or not os.path.isfile(path):
            continue
        site.write_replay_file(os.path.join(output, "runs"), record["run_id"], path)
        pages[record["run_id"]] = record["run_id"] + ".html"
    return pages


def embed(record, output):
    """The HTML embedding the record's replay page (student pages are in students/), or ""."""
    if not os.path.isfile(os.path.join(output, "runs", record["run_id"] + ".html")):
        return ""
    return ('<iframe class="replay" src="../runs/%s.html" loading="lazy" width="640" '
            'height="%d" title="replay of run %d"></iframe>'
            % (html.escape(record["run_id"]), HEIGHT, record["index"]))
