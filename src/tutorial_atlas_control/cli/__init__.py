"""The scripts' command lines: argument parsing, the error convention and exit codes.

Each script calls its module's main() (cli/<script>.py); what they share is offered here.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'convention': ['EXIT_INTERRUPTED', 'EXIT_REFUSED', 'add_bag_arguments', 'argument_type',
                   'check_bag_arguments', 'chosen_bag', 'print_error'],
    'environment': ['ENV_HINT', 'EXIT_BROKEN_PIPE', 'run_script'],
})
