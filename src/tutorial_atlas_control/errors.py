"""The package's exception hierarchy: one base, one subclass per concern."""


class AtlasControlError(Exception):
    """Base of every error this package raises on purpose.

    Command-line entry points catch it and print its message as one line.
    """


class BagAnalysisError(AtlasControlError):
    """A bag cannot be read or analyzed, or a report on it cannot be written.

    Shared by bags/ (records, reader, analysis, report), which analyze_bag.py
    runs as one tool; the message says what to do about it.
    """
