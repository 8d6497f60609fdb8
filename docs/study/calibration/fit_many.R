# Maximum-likelihood fits of every seed written by simulate_many.py: is the recovery data Eq. (3)/(4)?
#
# Usage: Rscript docs/study/calibration/fit_many.R FOLDER    (needs r-cran-ordinal and r-cran-lme4)
# Per seed: ordinal::clmm  category ~ condition + session + (1|participant) + (1|item)  per questionnaire (Laplace),
#           lme4::glmer    interventions ~ condition + session + (1|participant), Poisson, 10-point quadrature.
# Writes FOLDER/fits.csv (seed, model, est, se, sdP) and prints, per model, the mean estimate, the sd of the
# estimates over seeds against the mean standard error (near 1 when the data follow the model) and Wald coverage.
suppressMessages({
  library(ordinal)
  library(lme4)
})
folder <- commandArgs(trailingOnly = TRUE)[1]
ratings <- read.csv(file.path(folder, "ratings.csv"), stringsAsFactors = TRUE)
counts <- read.csv(file.path(folder, "counts.csv"), stringsAsFactors = TRUE)
as_factors <- function(x) {
  x$condition <- factor(x$condition, levels = c("off", "on"))
  x$session_index <- factor(x$session_index)
  x
}
rows <- list()
for (s in sort(unique(ratings$seed))) {
  for (q in c("mdmt", "tps_hri")) {
    x <- as_factors(ratings[ratings$seed == s & ratings$questionnaire == q, ])
    x$category <- factor(x$category, ordered = TRUE)
    f <- clmm(category ~ condition + session_index + (1 | participant) + (1 | item), data = x)
    co <- summary(f)$coefficients
    rows[[length(rows) + 1]] <- data.frame(seed = s, model = q, est = co["conditionon", 1],
      se = co["conditionon", 2], sdP = sqrt(VarCorr(f)$participant[1, 1]))
  }
  y <- as_factors(counts[counts$seed == s, ])
  g <- glmer(interventions ~ condition + session_index + (1 | participant), family = poisson, data = y,
             nAGQ = 10)
  co <- summary(g)$coefficients
  rows[[length(rows) + 1]] <- data.frame(seed = s, model = "counts", est = co["conditionon", 1],
    se = co["conditionon", 2], sdP = sqrt(VarCorr(g)$participant[1, 1]))
}
fits <- do.call(rbind, rows)
write.csv(fits, file.path(folder, "fits.csv"), row.names = FALSE)
for (m in unique(fits$model)) {
  z <- fits[fits$model == m, ]
  cat(sprintf("%-8s n=%d mean=%.3f sd(est)=%.3f mean(se)=%.3f ratio=%.2f wald-cover=%.2f sdP=%.2f\n",
              m, nrow(z), mean(z$est), sd(z$est), mean(z$se), sd(z$est) / mean(z$se),
              mean(abs(z$est - 1) <= 1.96 * z$se), mean(z$sdP)))
}
