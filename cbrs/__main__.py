from cbrs.cli import main

main()
