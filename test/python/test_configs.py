"""The configuration files as the node's parameter server reads them: roslaunch's rosparam
loads YAML with PyYAML (YAML 1.1), which takes a number such as 1.0e7 (no sign in the
exponent) for a string, where the offline tools' reader (yaml-cpp) takes it for a
number; the node then refuses the setting and stops. Every value of the bundled
configurations that reads as a number must be one for PyYAML too. Run by
test/system_tests.cmake under pytest."""

import glob
import os

import yaml

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
CONFIGS = sorted(
    glob.glob(os.path.join(REPO, "config", "*.yaml")) +
    glob.glob(os.path.join(REPO, "test", "config", "ok_*.yaml")) +
    glob.glob(os.path.join(REPO, "bench", "*.yaml")))


def numbers_read_as_strings(value, where=""):
    if isinstance(value, dict):
        for key, item in value.items():
            yield from numbers_read_as_strings(item, "%s/%s" % (where, key))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            yield from numbers_read_as_strings(item, "%s[%d]" % (where, index))
    elif isinstance(value, str):
        try:
            float(value)
        except ValueError:
            return
        if value.strip().lower() not in ("nan", "inf", "-inf", "+inf", "infinity"):
            yield "%s: %r" % (where, value)


def test_every_number_is_a_number_for_rosparam():
    assert CONFIGS, "no configuration found"
    found = []
    for path in CONFIGS:
        with open(path, encoding="utf-8") as f:
            for problem in numbers_read_as_strings(yaml.safe_load(f)):
                found.append("%s %s" % (os.path.relpath(path, REPO), problem))
    assert not found, ("numbers that rosparam reads as strings (write 1.0e+7, not "
                       "1.0e7):\n" + "\n".join(found))


def test_the_check_finds_what_it_must():
    assert list(numbers_read_as_strings(yaml.safe_load("a: {b: 1.0e7}"))) == ["/a/b: '1.0e7'"]
    assert not list(numbers_read_as_strings(yaml.safe_load("a: [1.0e+7, 2, x, '.nan']")))
