# Fit a cumulative link mixed model with ordinal::clmm and write its estimates as CSV.
#
# Usage: Rscript clmm_fit.R DATA.csv FORMULA OUT.csv [NAGQ]
#   DATA.csv  columns of the formula; the response is an integer category (higher = more), the others factors
#   FORMULA   e.g. "rating ~ temp + contact + (1|judge)"
#   OUT.csv   written with columns kind (fixed, threshold, ranef_sd), name, estimate, se
#   NAGQ      adaptive Gauss-Hermite quadrature points (default 10; only with a single random-effect term)
# Exit status 3 when the ordinal package is missing, so callers can tell "not installed" from a failed fit.

args <- commandArgs(trailingOnly = TRUE)
if (length(args) < 3) {
  stop("usage: Rscript clmm_fit.R DATA.csv FORMULA OUT.csv [NAGQ]")
}
if (!requireNamespace("ordinal", quietly = TRUE)) {
  message("R package 'ordinal' is not installed (Debian: apt-get install r-cran-ordinal)")
  quit(status = 3)
}
formula <- as.formula(args[2])
nagq <- if (length(args) >= 4) as.integer(args[4]) else 10L
data <- read.csv(args[1], stringsAsFactors = TRUE)
response <- all.vars(formula)[1]
data[[response]] <- factor(data[[response]], levels = sort(unique(data[[response]])), ordered = TRUE)
for (v in all.vars(formula)[-1]) {
  data[[v]] <- factor(data[[v]])
}
n_terms <- length(grep("|", attr(terms(formula), "term.labels"), fixed = TRUE))
fit <- if (n_terms == 1 && nagq > 1) {
  ordinal::clmm(formula, data = data, nAGQ = nagq)
} else {
  ordinal::clmm(formula, data = data)
}
s <- summary(fit)$coefficients
is_threshold <- rownames(s) %in% names(fit$alpha)
sds <- sapply(ordinal::VarCorr(fit), function(v) sqrt(v[1, 1]))
out <- rbind(
  data.frame(kind = ifelse(is_threshold, "threshold", "fixed"), name = rownames(s),
             estimate = s[, "Estimate"], se = s[, "Std. Error"]),
  data.frame(kind = "ranef_sd", name = names(sds), estimate = unname(sds), se = NA)
)
write.csv(out, args[3], row.names = FALSE)
