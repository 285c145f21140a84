"""Parameter sets: ``prototype`` holds the paper's numbers; the others are estimates."""
