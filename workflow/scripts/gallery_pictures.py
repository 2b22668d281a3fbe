"""The gallery's picture grid: per mesh the initial surface and every scheme's
last frame (rule ``gallery_pictures``, workflow/rules/gallery.smk)."""

import logging

from mcfbench.storage.frames import load_frames
from mcfbench.storage.records import read_record
from mcfbench.studies.gallery.plots import gallery_grid

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
plan = sm.params.plan
entries = {}
for path, settings in sm.params.expected.items():
    frames = path.replace("/runs/", "/frames/", 1).removesuffix(".json") + ".npz"
    entries[settings["mesh"], settings["scheme"]] = (read_record(path, settings=settings),
                                                     load_frames(frames))
gallery_grid(entries, [sm.output.png, sm.output.pdf], list(plan["meshes"]), plan["schemes"])
logging.info("wrote %s", ", ".join(sm.output))
