"""The scripts' command lines: argument parsing, the error convention and exit codes."""
