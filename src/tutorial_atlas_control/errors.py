"""The package's exception hierarchy: one base, one subclass per concern."""


class AtlasControlError(Exception):
    """Base of every error this package raises on purpose.

    Command-line entry points catch it and print its message as one line.
    """
