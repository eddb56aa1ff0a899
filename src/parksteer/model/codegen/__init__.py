"""Generated code: C from the symbolic equations, compiled and cached by a hash of the symbolic half."""
