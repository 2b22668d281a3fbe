"""The animation of one gallery run (rule ``gallery_movie``, workflow/rules/gallery.smk;
:func:`mcfbench.studies.gallery.run_movie`)."""

from mcfbench.studies.gallery import plots as gallery_plots

sm = snakemake  # noqa: F821
gallery_plots.run_movie(sm.input.record, sm.input.frames, sm.output.gif, sm.log[0])
