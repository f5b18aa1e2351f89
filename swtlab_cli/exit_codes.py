"""Exit codes of the ``swtlab`` command, documented in ``swtlab --help`` and the README."""

OK = 0  # the command did its job (a batch may still report runs it could not use)
USAGE = 2  # bad command line (argparse's own code)
BAD_INPUT = 3  # an InputError: the input could not be used at all, nothing processed
INTERNAL = 4  # an unexpected error inside swtlab outside any run: please report it

EPILOG = """exit codes:
  0  done (a batch may still list runs it could not use, each with file, stage and reason;
     swtlab results lists them as failed)
  2  bad command line
  3  bad input: nothing could be read or processed (the message names file, channel, problem)
  4  unexpected internal error outside any run (please report it with the command line)
"""
