"""The animation of one gallery run (rule ``gallery_movie``, workflow/rules/gallery.smk;
:func:`mcfbench.studies.gallery.run_movie`)."""

from mcfbench.studies import gallery

sm = snakemake  # noqa: F821
gallery.run_movie(sm.input.record, sm.input.frames, sm.output.gif, sm.log[0])
