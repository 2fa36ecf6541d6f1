"""pushval's Python side.

The `pushval` command itself is the Rust binary the wheel installs; this
package holds what a Python program needs to talk to it:

* `pushval.adapter`: the adapter kit. Write the step of a simulator, and the
  kit speaks the pushval-problem protocol (versions 1 and 2, one-shot and
  session) around it.

Standard library only.
"""

__all__ = ["adapter"]
