"""Views: widgets that only draw the document and forward user input."""
