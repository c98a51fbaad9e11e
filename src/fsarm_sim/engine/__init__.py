"""MuJoCo glue: model building, callbacks (thread-safe), native compilation."""
