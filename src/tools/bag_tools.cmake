# bag tools (filled in)
