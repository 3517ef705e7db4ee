# rostest node tests (filled in)
