"""The animation of one gallery run (rule ``gallery_movie``, workflow/rules/gallery.smk;
:func:`mcfbench.studies.gallery.run_movie`), from its record and frames in the run store."""

from mcfbench.storage.run_store import frames_path, record_path
from mcfbench.studies.gallery import plots as gallery_plots
from mcfbench.studies.gallery.plan import gallery_specs

sm = snakemake  # noqa: F821
spec = gallery_specs(sm.params.plan)[sm.wildcards.mesh, sm.wildcards.scheme]
gallery_plots.run_movie(record_path(spec), frames_path(spec), sm.output.gif, sm.log[0])
