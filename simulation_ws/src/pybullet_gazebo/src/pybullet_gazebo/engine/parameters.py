"""One way to read a typed, range-checked parameter, for plugin tags and node parameters alike.

A ParameterReader wraps a mapping of raw values: a `<plugin>`'s child tags as text, or ROS
parameters as the parameter server returns them (numbers, booleans or strings). Each read names
its parameter, the value and the allowed range when the value is unusable:

    reader = ParameterReader(plugin.params, "diff drive plugin 'p' (libx.so)", label="<%s>")
    reader.number("wheelDiameter", 0.15, above=0.0)
    -> ParameterError: diff drive plugin 'p' (libx.so): <wheelDiameter> is 0; it must be > 0.0
"""
import math


class ParameterError(ValueError):
    """A parameter's value cannot be used; the message names the parameter, the value and what
    is allowed."""


SDF_BOOLEANS = (("true", "1"), ("false", "0"))                     # SDF's and URDF's words
ROS_BOOLEANS = (("true", "1", "yes"), ("false", "0", "no"))


class ParameterReader:
    def __init__(self, values, where, label="%s", booleans=SDF_BOOLEANS):
        self.values = values            # key -> raw value (absent: the default is used)
        self.where = where              # who reads, for messages
        self.label = label              # how a key is written: "<%s>" for tags, "~%s" for ROS
        self.booleans = booleans        # (words for true, words for false), lower case

    def given(self, key) -> bool:
        return self.values.get(key) is not None

    def _fail(self, key, raw, requirement):
        raise ParameterError("%s: %s is %s; %s" % (self.where, self.label % key, raw, requirement))

    def text(self, key, default):
        raw = self.values.get(key)
        return default if raw is None else str(raw).strip()

    def number(self, key, default, minimum=None, above=None, maximum=None):
        """A finite float, >= minimum, > above and <= maximum where given."""
        raw = self.values.get(key)
        if raw is None:
            return default
        if isinstance(raw, bool):
            self._fail(key, raw, "give a number")
        try:
            value = float(raw.strip() if isinstance(raw, str) else raw)
        except (TypeError, ValueError):
            self._fail(key, raw, "give a number")
        if not math.isfinite(value):
            self._fail(key, raw, "give a finite number")
        if minimum is not None and value < minimum:
            self._fail(key, raw, "it must be >= %s" % minimum)
        if above is not None and value <= above:
            self._fail(key, raw, "it must be > %s" % above)
        if maximum is not None and value > maximum:
            self._fail(key, raw, "it must be <= %s" % maximum)
        return value

    def integer(self, key, default, minimum=None):
        raw = self.values.get(key)
        if raw is None:
            return default
        value = self.number(key, default, minimum=minimum)
        if value != int(value):
            self._fail(key, raw, "give a whole number")
        return int(value)

    def boolean(self, key, default):
        raw = self.values.get(key)
        if raw is None:
            return default
        if isinstance(raw, bool):
            return raw
        word = str(raw).strip().lower()
        if word in self.booleans[0]:
            return True
        if word in self.booleans[1]:
            return False
        self._fail(key, raw, "write true or false")

    def choice(self, key, default, choices):
        """One of the words `choices` (lower case; a boolean reads as true/false, as roslaunch
        hands over `value="true"`)."""
        raw = self.values.get(key)
        if raw is None:
            return default
        word = str(raw).strip().lower()
        if word not in choices:
            self._fail(key, raw, "write one of: %s" % ", ".join(choices))
        return word
