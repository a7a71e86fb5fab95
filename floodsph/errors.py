"""User-facing error types."""


class InputError(Exception):
    """A problem with the user's input (file, key, value), reported as one plain message.

    The command line prints ``str(error)`` without a traceback and exits with status 2. The
    message names the file, the key path (``inflows[0].hydrograph``) or the value at fault.
    """
