# The reproduction report (results/paper/), built from the result files.
REPORT_TARGETS = []
